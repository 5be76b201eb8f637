"""The compiled pass of GraphDistNet-3D (models/graphdistnet3d/fused3d*.py) against the torch
network: float64 d̂ and ∂d̂/∂q to 1e-9 relative (shipped weights and random networks of other
sizes, robot graphs of mixed degrees, several tiles, near-contact configurations), ∂d̂/∂q
against central differences, float32 against a float64 truth, and the settings' refusals."""

from __future__ import annotations

import dataclasses
import os
from pathlib import Path

import numpy as np
import pytest
import torch

from gdnplan.arm3d import Checker3D, Scene3D, load_robot3d, random_boxes
from gdnplan.data.samples3d import obstacle_robot
from gdnplan.errors import InputError
from gdnplan.graph3d import neighbourhoods, robot_graph3d
from gdnplan.models.graphdistnet import fused as planar_fused
from gdnplan.models.graphdistnet3d import (
    GraphDistNet3D,
    GraphDistNet3DConfig,
    GraphDistNet3DModel,
    fused3d,
    load_graphdistnet3d,
)

WEIGHTS = Path(__file__).parents[1] / "weights" / "ur5e_boxes3d_preliminary.safetensors"


def test_ci_runs_the_compiled_path():
    """In CI the pass is a compiled numba function (not skipped, not run as Python)."""
    if os.environ.get("CI") != "true" and not planar_fused.AVAILABLE:
        pytest.skip("numba is not installed (CI must have it: this test fails there)")
    import numba

    assert planar_fused.AVAILABLE
    assert isinstance(fused3d._kernels.network, numba.core.registry.CPUDispatcher)
    assert load_graphdistnet3d(WEIGHTS).fused  # the default inference path


needs_numba = pytest.mark.skipif(  # in CI they run, and fail without numba
    not planar_fused.AVAILABLE and os.environ.get("CI") != "true", reason="numba not installed"
)


@pytest.fixture(scope="module")
def robot():
    return load_robot3d("ur5e")


@pytest.fixture(scope="module")
def scene(robot):
    return random_boxes(robot, 20, seed=4)


def configurations(robot, scene, n: int = 24, near: int = 12) -> np.ndarray:
    """n random configurations and the ``near`` of 400 others closest to contact (coal)."""
    pool = robot.random_configurations(400, np.random.default_rng(7))
    bare = Checker3D(Scene3D(obstacle_robot(robot.name), scene.obstacles))
    closest = np.argsort(np.abs(bare.evaluate(pool).distance))[:near]
    return np.concatenate([robot.random_configurations(n, np.random.default_rng(3)), pool[closest]])


def pair(net: GraphDistNet3D, dtype: torch.dtype, card: dict | None = None):
    """The compiled and the torch model of one network, both in ``dtype``, learned part only."""
    kwargs = {"card": card, "dtype": dtype, "self_collision": False}
    net = net.to(dtype)
    fused = GraphDistNet3DModel(net, fused=True, **kwargs)
    return fused, GraphDistNet3DModel(net, fused=False, **kwargs)


def assert_same(fused, ref, scene, q, rtol: float = 1e-9) -> None:
    d, g = fused.learned_distance_and_grad(scene, q)
    d_ref, g_ref = ref.learned_distance_and_grad(scene, q)
    scale = np.abs(d_ref).max()
    np.testing.assert_allclose(d, d_ref, rtol=rtol, atol=rtol * scale)
    np.testing.assert_allclose(g, g_ref, rtol=rtol, atol=rtol * np.abs(g_ref).max())
    d_alone = fused.learned_distance(scene, q)
    np.testing.assert_allclose(d_alone, d_ref, rtol=rtol, atol=rtol * scale)


@needs_numba
def test_shipped_weights_equal_torch_in_float64(robot, scene):
    shipped = load_graphdistnet3d(WEIGHTS, fused=False)
    fused, ref = pair(shipped.net, torch.float64, shipped.card)
    q = configurations(robot, scene)
    assert fused.fused and not ref.fused
    assert_same(fused, ref, scene, q)  # 36 configurations: 9 tiles of 4


@needs_numba
@pytest.mark.parametrize(
    "options",
    [
        # H ≠ P, one hidden product, three layers, head of another width, 3 candidates
        {"rim": 6, "hidden": 16, "mlp": (24, 24), "readout": (20, 20), "layers": 3, "cross_k": 2},
        # no hidden product in h_k, one head layer, more candidates than one box has nodes
        {"rim": 4, "hidden": 8, "mlp": (12,), "readout": (6,), "layers": 2, "cross_k": 9},
    ],
)
def test_random_networks_equal_torch_in_float64(robot, options):
    torch.manual_seed(1)
    net = GraphDistNet3D(GraphDistNet3DConfig(scale=1.2, **options))
    fused, ref = pair(net, torch.float64)
    one_box = random_boxes(robot, 1, seed=2)  # 8 obstacle nodes: C = min(k + 1, 8)
    for scene in (random_boxes(robot, 20, seed=5), one_box):
        assert_same(fused, ref, scene, configurations(robot, scene, n=10, near=6))


@needs_numba
def test_mixed_degrees_equal_torch_in_float64(robot, scene):
    """A robot graph whose nodes have 3 to 6 neighbours (masked, padded) through the pass."""
    torch.manual_seed(2)
    net = GraphDistNet3D(GraphDistNet3DConfig(scale=1.2, rim=4, hidden=16, mlp=(16,) * 3)).double()
    graph = robot_graph3d(robot, 4)
    n = graph.n_nodes
    src, slot = np.nonzero(graph.nbr_mask)
    extra = [(i, (i * 7 + 11) % n) for i in range(0, n, 2) if (i * 7 + 11) % n != i]
    extra += [(i, (i + 40) % n) for i in range(0, n, 5)]
    edges = np.unique(np.sort(np.r_[np.c_[src, graph.nbr[src, slot]], extra], 1), axis=0)
    nbr, mask = neighbourhoods(n, edges)
    assert len(set(mask.sum(1))) >= 3
    mixed = dataclasses.replace(graph, nbr=nbr, nbr_mask=mask)
    feats = GraphDistNet3DModel(net, dtype=torch.float64, fused=False)._cache(scene).feats
    nodes = mixed.positions(configurations(robot, scene, n=14, near=4))
    d, g = fused3d.run(fused3d.pack(net, feats, mixed, np.float64), nodes, grad=True)
    x = torch.as_tensor(nodes).requires_grad_(True)
    d_ref = net(x, torch.as_tensor(nbr), torch.as_tensor(mask), feats)
    (g_ref,) = torch.autograd.grad(d_ref.sum(), x)
    d_ref, g_ref = d_ref.detach().numpy(), g_ref.numpy()
    np.testing.assert_allclose(d, d_ref, rtol=1e-9, atol=1e-9 * np.abs(d_ref).max())
    np.testing.assert_allclose(g, g_ref, rtol=1e-9, atol=1e-9 * np.abs(g_ref).max())


@needs_numba
def test_gradient_matches_finite_differences(robot, scene):
    shipped = load_graphdistnet3d(WEIGHTS, fused=False)
    fused, _ = pair(shipped.net, torch.float64, shipped.card)
    qs = configurations(robot, scene, n=2, near=2)
    _, g = fused.learned_distance_and_grad(scene, qs)
    h = 1e-7  # d̂ is piecewise smooth (LeakyReLU): a larger step may cross a kink
    d = fused.learned_distance
    for b, q in enumerate(qs):
        fd = [(d(scene, q + e) - d(scene, q - e))[0] / (2 * h) for e in np.eye(robot.dof) * h]
        np.testing.assert_allclose(g[b], fd, rtol=1e-4, atol=1e-8)


@needs_numba
def test_float32_as_accurate_as_torch_float32(robot, scene):
    """Against the float64 network: the compiled float32 pass's d̂ and gradient errors are of
    the size of the torch float32 network's own (not 1e-9: float32 rounding near LeakyReLU
    kinks takes the other slope now and then, in either path)."""
    shipped = load_graphdistnet3d(WEIGHTS, fused=False)
    truth = GraphDistNet3DModel(shipped.net.double(), dtype=torch.float64, fused=False)
    q = configurations(robot, scene, n=30, near=10)
    d64, g64 = truth.learned_distance_and_grad(scene, q)
    errors = {}
    for fused in (True, False):
        net = load_graphdistnet3d(WEIGHTS, fused=False).net
        model = GraphDistNet3DModel(net, dtype=torch.float32, fused=fused)
        d, g = model.learned_distance_and_grad(scene, q)
        rel = np.linalg.norm(g - g64, axis=1) / np.linalg.norm(g64, axis=1)
        errors[fused] = (np.abs(d - d64).max(), np.percentile(rel, 90))
    (d_f, g_f), (d_r, g_r) = errors[True], errors[False]
    assert d_f < 1e-5 and d_f <= 3 * d_r + 1e-7, errors
    assert g_f < 1e-3 and g_f <= 3 * g_r + 1e-6, errors


@needs_numba
def test_settings_and_refusals(robot, scene):
    torch.manual_seed(0)
    uneven = GraphDistNet3D(GraphDistNet3DConfig(scale=1.2, layers=1, mlp=(32, 16)))
    assert fused3d.refusal(uneven.config) is not None
    assert not GraphDistNet3DModel(uneven).fused  # the default falls back to torch
    with pytest.raises(InputError, match="fused"):
        GraphDistNet3DModel(uneven, fused=True)
    assert GraphDistNet3DModel(uneven, fused=None).distance(scene, np.zeros(6)).shape == (1,)

    @dataclasses.dataclass(frozen=True)
    class Extended(GraphDistNet3DConfig):  # a config option the pass does not implement
        pooling: str = "attention"

    assert fused3d.refusal(Extended()) is None  # at its default: the network it computes
    assert "pooling" in fused3d.refusal(Extended(pooling="softmin"))
