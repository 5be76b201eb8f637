"""Every DistanceModel's gradient, and the CasADi callback's Jacobian, against central differences.

Truth: g_j ≈ (d(q + h e_j) − d(q − h e_j)) / 2h on seeded random configurations of a few scenes.
Kinks: coal's signed distance is a minimum over link–obstacle pairs (and, within a pair, over
features), so it is only piecewise smooth; a learned model may have ReLU kinks. A configuration
is kept only where d is smooth across [q − h e_j, q + h e_j] for every joint j, detected by
the one-sided slopes: for a C² function (d(q + h e) − d(q)) / h and (d(q) − d(q − h e)) / h
differ by h·|∂²d| (tiny), while a kink inside the step (the closest pair changing, a ReLU
switching) makes them differ by the jump of the slope. For coal the closest link must also stay
the same at q ± h e_j. At least ``MIN_KEPT`` of the draws must survive, so the filter cannot
hide a wrong gradient everywhere. A slope change s below the threshold (a faint kink) can move
the central difference by up to s / 2, so that much is allowed on top of the tolerance.

Shipped float32 networks are checked through their float64 copies (the same weights) to 1e-6,
and their float32 gradients against the copies' within float32 rounding.
"""

from __future__ import annotations

import copy
from collections.abc import Callable

import casadi
import numpy as np
import pytest
import torch

import gdnplan as gp
from gdnplan.casadi_bridge import DistanceCallback
from gdnplan.models import clearancenet as cn
from gdnplan.models.diffco import DiffCo
from gdnplan.models.graphdistnet import GraphDistNet, GraphDistNetConfig, GraphDistNetModel

MIN_KEPT = 0.8  # share of random configurations that must be smooth within the FD step


def central_differences(
    f: Callable[[np.ndarray], np.ndarray], q: np.ndarray, h: float
) -> tuple[np.ndarray, np.ndarray]:
    """Central differences (B, n) of f: (B, n) → (B,) and the one-sided slope jump (B, n)."""
    f0, cols, jumps = f(q), [], []
    for e in np.eye(q.shape[1]):
        up, down = f(q + h * e), f(q - h * e)
        cols.append((up - down) / (2 * h))
        jumps.append(np.abs((up - f0) - (f0 - down)) / h)
    return np.stack(cols, 1), np.stack(jumps, 1)


def assert_gradient(model, scene, q, h=1e-6, kink=1e-3, atol=1e-6, rtol=1e-5, closest=None):
    """distance_and_grad's gradient equals central differences where d is smooth in the step;
    ``closest(q)`` (B,) names the closest part, which must not change within the step."""
    d, g = model.distance_and_grad(scene, q)
    np.testing.assert_allclose(d, model.distance(scene, q), rtol=1e-6, atol=1e-9)
    fd, jump = central_differences(lambda x: model.distance(scene, x), q, h)
    smooth = (jump <= kink).all(1)
    if closest is not None:
        c = closest(q)
        for e in np.eye(q.shape[1]):
            smooth &= (closest(q + h * e) == c) & (closest(q - h * e) == c)
    assert smooth.mean() >= MIN_KEPT, f"only {smooth.mean():.0%} of the draws are smooth"
    # a slope change s inside the step moves the central difference by at most s / 2
    bound = atol + rtol * np.abs(fd) + jump / 2
    bad = np.abs(g - fd) > bound
    assert not bad[smooth].any(), (g[smooth & bad.any(1)], fd[smooth & bad.any(1)])


def assert_float64_twin(model, twin, scene, q):
    """A shipped float32 network: its float64 copy (the same weights) against central
    differences, then the float32 gradient, as planners get it, against the copy's within
    float32 rounding (FD on float32 itself would only see rounding over h: ≈ 1e-7 m / h)."""
    _, g64 = twin.distance_and_grad(scene, q)
    scale = max(1.0, np.abs(g64).max())
    assert_gradient(twin, scene, q, kink=1e-3 * scale, atol=1e-6 * scale)
    _, g32 = model.distance_and_grad(scene, q)
    np.testing.assert_allclose(g32, g64, rtol=1e-3, atol=1e-4 * scale)


class Scaled:
    """A model whose gradient is off by a factor: what the check must reject."""

    name = "scaled"

    def __init__(self, model, factor: float):
        self.model, self.factor = model, factor

    def distance(self, scene, q):
        return self.model.distance(scene, q)

    def distance_and_grad(self, scene, q):
        d, g = self.model.distance_and_grad(scene, q)
        return d, g * self.factor


def test_the_check_rejects_a_gradient_off_by_one_percent():
    scene = gp.make_scene("d", seed=5)
    q = scene.robot.sample(50, seed=8)
    assert_gradient(Scaled(gp.CoalModel(), 1.0), scene, q, atol=1e-5)
    with pytest.raises(AssertionError):
        assert_gradient(Scaled(gp.CoalModel(), 1.01), scene, q, atol=1e-5)


# -------------------------------------------------------------------- coal exact distance
@pytest.mark.parametrize(("env", "seed"), [("a", 5), ("b", 5), ("c", 5), ("d", 5), ("e", 5)])
def test_coal_gradient_matches_central_differences(env, seed):
    scene = gp.make_scene(env, seed=seed)
    q = scene.robot.sample(200, seed=8)

    def closest_link(x):
        return np.argmin(gp.signed_distance(scene, x, per_link=True), axis=1)

    assert_gradient(gp.CoalModel(), scene, q, closest=closest_link, atol=1e-5)


def test_coal_gradient_on_the_ur5e_fetch_scene():
    scene = gp.make_scene("fetch", seed=0, gripper="holding")
    q = scene.robot.sample(100, seed=2)

    def closest_link(x):
        return np.argmin(gp.signed_distance(scene, x, per_link=True), axis=1)

    assert_gradient(gp.CoalModel(), scene, q, closest=closest_link, atol=1e-5)


def test_coal_per_link_gradient_matches_central_differences():
    scene = gp.make_scene("d", seed=2)
    q = scene.robot.sample(60, seed=1)
    _, g_links = gp.signed_distance_and_grad(scene, q, per_link=True)
    for k in range(scene.robot.n_links):  # each link's distance: a function of its own

        class Link:
            def distance(self, scene, x, k=k):
                return gp.signed_distance(scene, x, per_link=True)[:, k]

            def distance_and_grad(self, scene, x, k=k):
                d, g = gp.signed_distance_and_grad(scene, x, per_link=True)
                return d[:, k], g[:, k]

        assert_gradient(Link(), scene, q, atol=1e-5)
    assert np.all(g_links[:, 0, 1:] == 0)  # link 1 does not move with the joints after it


# -------------------------------------------------------------------- GraphDistNet
@pytest.mark.parametrize("weights", ["a", "d", "ur5e"])
def test_shipped_graphdistnet_gradient_matches_central_differences(weights):
    model = gp.load_model(weights)
    scene = gp.make_scene("fetch" if weights == "ur5e" else weights, seed=3)
    q = scene.robot.sample(20, seed=4)
    twin = GraphDistNetModel(copy.deepcopy(model.net), model.card, dtype=torch.float64)
    assert_float64_twin(model, twin, scene, q)


@pytest.mark.parametrize(
    "changes",
    [
        {},
        {"cross_k": 2},
        {"two_way": False},
        {"node_distance": True},
        {"node_distance": True, "two_way": False, "min_readout": True},
        {"node_distance": True, "min_readout": True, "tau_min": 0.02},
        {"node_distance": True, "min_readout": True, "correction_band": 0.3, "probe_split": 3},
    ],
)
def test_graphdistnet_variants_gradient_matches_central_differences(changes):
    """Every forward path (one-/two-way, node distances, min readout, band) on random weights."""
    scene = gp.make_scene("e", seed=5)
    torch.manual_seed(0)
    config = GraphDistNetConfig.smooth(scale=scene.robot.reach, **changes)
    net = GraphDistNet(config)
    if config.min_readout:  # a readout MLP that is not yet zero
        torch.nn.init.normal_(net.head[-1].weight, std=0.3)
    model = GraphDistNetModel(net, dtype=torch.float64)
    q = scene.robot.sample(5, seed=2)
    scale = max(1.0, np.abs(model.distance_and_grad(scene, q)[1]).max())
    assert_gradient(model, scene, q, kink=1e-3 * scale, atol=1e-8 * scale)


# -------------------------------------------------------------------- ClearanceNet
@pytest.mark.parametrize("env", ["a", "d"])
def test_shipped_clearancenet_gradient_matches_central_differences(env):
    model = gp.load_model(f"clearancenet_{env}")
    scene = gp.make_scene(env, seed=4)
    q = scene.robot.sample(20, seed=1)
    twin = cn.ClearanceNetModel(copy.deepcopy(model.net).double(), model.card)
    assert_float64_twin(model, twin, scene, q)


@pytest.mark.parametrize("env", ["b", "d"])
def test_random_clearancenet_gradient_matches_central_differences(env):
    torch.manual_seed(0)
    config = cn.ClearanceNetConfig.for_env(env, hidden=(32, 32))
    model = cn.ClearanceNetModel(cn.ClearanceNet(config).double())
    scene = gp.make_scene(env, seed=4)
    q = scene.robot.sample(10, seed=1)
    assert_gradient(model, scene, q, kink=1e-3, atol=1e-8)


# -------------------------------------------------------------------- DiffCo
@pytest.mark.parametrize(("env", "n"), [("a", 800), ("c", 600)])
def test_diffco_gradient_matches_central_differences(env, n):
    """The kernel score and its fitted (distance-scaled) variant, 2 and 7 joints."""
    scene = gp.make_scene(env)
    model = DiffCo.train(scene, n=n, seed=1)
    q = scene.robot.sample(20, seed=4)
    for m in (model, model.fitted()):
        scale = np.abs(m.distance_and_grad(scene, q)[1]).max()
        assert_gradient(m, scene, q, kink=1e-3 * max(scale, 1.0), atol=1e-5 * scale)


# -------------------------------------------------------------------- the CasADi callback
class SmoothModel:
    """Stand-in differentiable DistanceModel: d(q) = 0.5 + Σ_j a_j sin(q_j + b_j)."""

    name = "smooth"

    def __init__(self, dof: int):
        rng = np.random.default_rng(0)
        self.a, self.b = rng.uniform(0.1, 0.3, dof), rng.uniform(0, 3, dof)

    def distance(self, scene, q):
        return 0.5 + np.sin(np.atleast_2d(q) + self.b) @ self.a

    def distance_and_grad(self, scene, q):
        q = np.atleast_2d(q)
        return self.distance(scene, q), np.cos(q + self.b) * self.a


def callback_functions(cb: DistanceCallback, size: int) -> tuple[casadi.Function, casadi.Function]:
    x = casadi.MX.sym("x", size)
    y = cb(x)
    return casadi.Function("f", [x], [y]), casadi.Function("J", [x], [casadi.jacobian(y, x)])


def casadi_differences(f: casadi.Function, x: np.ndarray, h: float) -> tuple[np.ndarray, float]:
    """Central-difference Jacobian (rows, len(x)) of a CasADi function, and its largest
    one-sided slope jump (a kink inside the step)."""
    f0, cols, jump = np.array(f(x)).ravel(), [], 0.0
    for i in range(len(x)):
        dx = np.zeros_like(x)
        dx[i] = h
        up, down = np.array(f(x + dx)).ravel(), np.array(f(x - dx)).ravel()
        cols.append((up - down) / (2 * h))
        jump = max(jump, float(np.abs((up - f0) - (f0 - down)).max() / h))
    return np.stack(cols, 1), jump


@pytest.mark.parametrize(
    ("model", "per_link"), [("smooth", False), ("coal", False), ("coal", True)]
)
def test_callback_jacobian_equals_finite_differences(model, per_link):
    scene = gp.make_scene("d", seed=3)
    dof, k = scene.robot.dof, 4
    m = SmoothModel(dof) if model == "smooth" else gp.CoalModel()
    cb = DistanceCallback("d", m, scene, k, per_link=per_link)
    f, jac = callback_functions(cb, k * dof)
    x = scene.robot.sample(k, seed=1).ravel()
    J = np.array(jac(x))
    rows = scene.robot.n_links if per_link else 1
    assert J.shape == (k * rows, k * dof)
    fd, jump = casadi_differences(f, x, 1e-6)
    assert jump < 1e-3  # these draws are away from kinks (seeded: a fixed, checked set)
    np.testing.assert_allclose(J, fd, atol=1e-6)
    # block-diagonal: distance rows of waypoint t only depend on waypoint t
    assert jac.sparsity_out(0).nnz() == k * rows * dof


def test_graphdistnet_callback_jacobian_equals_the_model_gradient_and_finite_differences():
    scene = gp.make_scene("a")
    model = gp.load_model("a")
    cb = DistanceCallback("d", model, scene, 3)
    f, jac = callback_functions(cb, 6)
    q = scene.robot.sample(3, seed=4)
    J = np.array(jac(q.ravel()))
    _, g = model.distance_and_grad(scene, q)
    for t in range(3):  # the bridge places each gradient in its diagonal block, exactly
        np.testing.assert_allclose(J[t, 2 * t : 2 * t + 2], g[t], rtol=1e-12)
    # the shipped float32 network: finite differences agree up to rounding over h = 1e-3
    fd, jump = casadi_differences(f, q.ravel(), 1e-3)
    scale = np.abs(g).max()
    assert jump < 0.05 * scale
    np.testing.assert_allclose(J, fd, atol=2e-3 * scale, rtol=2e-2)
