"""The whole-network pass of GraphDistNet (models/graphdistnet/fused_net.py) against the torch
reference path (``fused=False``: autograd through :meth:`GraphDistNet.lean`). Every shipped
weights file the pass serves (soft-kNN: two-way b; one-way with node distances and the soft
minimum d, e and ur5e, the planar fetch's, since 2026-12-04; a and c are two-way with node
distances, which the pass leaves to the ring-message kernels) and
random one-way networks with node distances (each option), random and near-contact
configurations, more than one tile. Float64: d̂ and ∂d̂/∂q agree to 1e-9 relative (the same
function up to summation order). Float32 against a float64 truth: the yardstick is the
reference's own float32 error. d̂ agrees with float64 to ~1e-6 m in both (asserted: 2e-6 ·
scale); single gradients do not reach 1e-6 relative in either path, because float32 rounding
flips pre-activations within ~1e-7 of a LeakyReLU kink onto the other slope (over the 40
configurations here, on 2026-12-02 with the networks shipped then (d, e one-way without node
distances, b and ur5e two-way), the 90th-percentile
relative gradient error was, whole pass / reference, 1.9e-6 / 3.3e-6 (b), 3.7e-6 / 6.1e-6 (d),
3.6e-6 / 7.1e-6 (e), 1.2e-5 / 1.1e-5 (ur5e); the worst 1.6e-5 / 1.1e-4, 1.7e-3 / 1.7e-3, 3.6e-5
/ 4.7e-5, 6.7e-5 / 1.1e-4; the largest d̂ error 1.3e-6 m or less in both). Asserted: the whole
pass's 90th percentile under 1e-4 and at most 3× the reference's.
"""

import os

import numpy as np
import pytest
import torch
from hypothesis import given, settings
from hypothesis import strategies as st

import gdnplan as gp
from gdnplan.models.graphdistnet import (
    GraphDistNet,
    GraphDistNetConfig,
    GraphDistNetModel,
    fused_net,
)
from gdnplan.models.graphdistnet import fused as fused_kernel

SERVED = {"b": "b", "d": "d", "e": "e", "ur5e": "fetch"}  # weights the pass serves: scene


def test_ci_runs_the_compiled_path():
    """In CI the kernels are compiled numba functions (not skipped, not run as Python)."""
    if os.environ.get("CI") != "true" and not fused_kernel.AVAILABLE:
        pytest.skip("numba is not installed (CI must have it: this test fails there)")
    import numba

    assert fused_kernel.AVAILABLE
    assert isinstance(fused_net._kernels.network, numba.core.registry.CPUDispatcher)


needs_numba = pytest.mark.skipif(  # in CI they run, and fail without numba
    not fused_kernel.AVAILABLE and os.environ.get("CI") != "true", reason="numba not installed"
)


def configurations(scene: gp.Scene, n: int, near: int = 16) -> np.ndarray:
    """n random configurations and the ``near`` of 400 others closest to contact (coal)."""
    pool = scene.robot.sample(400, seed=7)
    closest = np.argsort(np.abs(gp.signed_distance(scene, pool)))[:near]
    return np.concatenate([scene.robot.sample(n, seed=3), pool[closest]])


def pair(weights: str, dtype: torch.dtype) -> tuple[GraphDistNetModel, GraphDistNetModel]:
    """The whole-pass and the reference model of a shipped weights file, both in ``dtype``."""
    loaded = gp.load_model(weights)
    kwargs = {"card": loaded.card, "dtype": dtype}
    return GraphDistNetModel(loaded.net, fused=True, **kwargs), GraphDistNetModel(
        loaded.net, fused=False, **kwargs
    )


@needs_numba
@pytest.mark.parametrize("weights", sorted(SERVED))
def test_whole_pass_equals_reference_in_float64(weights):
    scene = gp.make_scene(SERVED[weights], seed=0)
    whole, reference = pair(weights, torch.float64)
    packed = whole._graphs(scene).whole
    assert packed is not None  # the pass under test serves this network
    rows = packed.net.ring.shape[1]  # per configuration: robot nodes (+ obstacle nodes, two-way)
    two_way = whole.config.two_way
    assert rows == whole._graphs(scene).robot.n_nodes + two_way * len(packed.net.xo)
    tile = fused_net.TILE_ROWS // (3 * rows)
    q = configurations(scene, n=max(64, tile + 8))
    assert len(q) > tile  # more than one tile
    d, g = whole.distance_and_grad(scene, q)
    d_ref, g_ref = reference.distance_and_grad(scene, q)
    assert np.abs(d_ref).min() < 0.05  # near-contact configurations are in the set
    np.testing.assert_allclose(d, d_ref, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(g, g_ref, rtol=1e-9, atol=1e-9 * np.abs(g_ref).max())
    np.testing.assert_allclose(whole.distance(scene, q), d, rtol=1e-12, atol=1e-14)
    d_def, grad = whole.distance_deferred_grad(scene, q)
    np.testing.assert_array_equal(d_def, whole.distance(scene, q))
    np.testing.assert_allclose(grad(), g, rtol=1e-12, atol=1e-14)


@needs_numba
@pytest.mark.parametrize("weights", sorted(SERVED))
def test_whole_pass_float32_is_as_accurate_as_the_reference(weights):
    scene = gp.make_scene(SERVED[weights], seed=1)
    q = configurations(scene, n=24)
    exact = pair(weights, torch.float64)[1].distance_and_grad(scene, q)
    errors = []
    for model in pair(weights, torch.float32):
        d, g = model.distance_and_grad(scene, q)
        np.testing.assert_allclose(d, exact[0], atol=2e-6 * model.config.scale)
        errors.append(np.abs(g - exact[1]).max(1) / np.abs(exact[1]).max(1))
    whole_err, reference_err = (np.quantile(e, 0.9) for e in errors)
    assert whole_err < 1e-4
    assert whole_err <= 3 * reference_err + 1e-6


def test_whole_pass_serves_one_way_node_distances_not_two_way():
    names = ("a", "b", "c", "d", "e", "ur5e")
    served = {w for w in names if fused_net.serves(gp.load_model(w).config)}
    assert served == set(SERVED)  # a and c: two-way with node distances, the ring-message kernels
    one_way = GraphDistNetConfig(two_way=False, node_distance=True, min_readout=True)
    assert fused_net.serves(one_way) == fused_kernel.AVAILABLE
    assert not fused_net.serves(GraphDistNetConfig(two_way=True, node_distance=True))
    assert not fused_net.serves(GraphDistNetConfig(mlp=(64, 64)))  # edge MLP wider than h
    scene = gp.make_scene("d", seed=0)
    assert gp.load_model("d")._graphs(scene).whole is not None or not fused_kernel.AVAILABLE
    reference = GraphDistNetModel(gp.load_model("d").net, fused=False)
    assert reference._graphs(scene).whole is None


@needs_numba
def test_threads_split_the_batch_on_tiles_with_the_same_result():
    scene = gp.make_scene("fetch", seed=0)
    loaded = gp.load_model("ur5e")
    q = scene.robot.sample(150, seed=2)  # several tiles, an uneven split
    one, two = (GraphDistNetModel(loaded.net, card=loaded.card, threads=n) for n in (1, 2))
    d, g = one.distance_and_grad(scene, q)
    d2, g2 = two.distance_and_grad(scene, q)
    np.testing.assert_array_equal(d2, d)
    np.testing.assert_array_equal(g2, g)
    np.testing.assert_array_equal(two.distance(scene, q), one.distance(scene, q))
    single = two.distance(scene, q[:1])  # one tile: one thread, as the one-thread model
    np.testing.assert_array_equal(single, one.distance(scene, q[:1]))
    # a batch of one runs other BLAS kernels (gemv-like shapes) than a full tile: float32 rounding
    np.testing.assert_allclose(single, d[:1], rtol=1e-6, atol=1e-7)


DISTANCE_AWARE = {  # one-way networks with node distances: each option the pass computes
    "node distances": {"node_distance": True},
    "soft minimum": {"node_distance": True, "min_readout": True},
    "probe points": {"node_distance": True, "min_readout": True, "probe_split": 3},
    "band": {"node_distance": True, "min_readout": True, "probe_split": 2, "correction_band": 0.05},
}


def distance_aware(env: str, seed: int, **options) -> tuple[GraphDistNetModel, GraphDistNetModel]:
    """Whole-pass and reference models (float64) of a random one-way network with ``options``,
    every parameter non-trivial (the soft-minimum head's last layer starts at zero)."""
    torch.manual_seed(seed)
    scale = gp.make_scene(env, seed=0).robot.reach
    net = GraphDistNet(GraphDistNetConfig(two_way=False, scale=scale, **options))
    torch.nn.init.normal_(net.head[-1].weight, std=0.3)
    card = {"env": env}
    return (GraphDistNetModel(net, card=card, dtype=torch.float64, fused=f) for f in (True, False))


@needs_numba
@pytest.mark.parametrize("options", sorted(DISTANCE_AWARE))
@pytest.mark.parametrize("env, seed", [("d", 0), ("e", 3), ("b", 11)])
def test_whole_pass_equals_reference_with_node_distances(options, env, seed):
    """Values and gradients of the distance-aware one-way networks, random and near-contact
    configurations (inside obstacles too: negative node distances), more than one tile."""
    scene = gp.make_scene(env, seed=seed)
    whole, reference = distance_aware(env, seed, **DISTANCE_AWARE[options])
    assert whole._graphs(scene).whole is not None
    q = configurations(scene, n=96)
    d, g = whole.distance_and_grad(scene, q)
    d_ref, g_ref = reference.distance_and_grad(scene, q)
    assert (gp.signed_distance(scene, q) < 0).any()  # penetrating configurations are in the set
    np.testing.assert_allclose(d, d_ref, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(g, g_ref, rtol=1e-9, atol=1e-9 * np.abs(g_ref).max())
    np.testing.assert_allclose(whole.distance(scene, q), d, rtol=1e-12, atol=1e-14)


@needs_numba
def test_whole_pass_gradient_with_node_distances_matches_finite_differences():
    """The band network (every distance-aware term) against central differences of d̂ itself
    (a step of 1e-7 rad: d̂ is piecewise smooth, and 1e-6 crosses a kink on these samples)."""
    scene = gp.make_scene("d", seed=2)
    whole, _ = distance_aware("d", 2, **DISTANCE_AWARE["band"])
    q = configurations(scene, n=6, near=6)
    _, g = whole.distance_and_grad(scene, q)
    eps = 1e-7
    for j in range(q.shape[1]):
        step = np.zeros(q.shape[1])
        step[j] = eps
        fd = (whole.distance(scene, q + step) - whole.distance(scene, q - step)) / (2 * eps)
        np.testing.assert_allclose(g[:, j], fd, rtol=1e-5, atol=1e-6)


@needs_numba
@settings(max_examples=60, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    partners=st.integers(1, 12),
    cand=st.integers(1, 6),
    ties=st.booleans(),
    single=st.booleans(),
)
def test_point_parallel_candidates_equal_the_insertion_search(seed, partners, cand, ties, single):
    """The tile's candidates (vectorised over its points) are :func:`_nearest`'s, point by
    point: the same rows in the same order (ties to the lower row), d² and log φ, also with
    fewer partners than candidates (padded) and with repeated partners (exact ties)."""
    from gdnplan.models.graphdistnet.fused_net_kernels import _nearest
    from gdnplan.models.graphdistnet.fused_search import point_candidates

    dtype = np.float32 if single else np.float64
    rng = np.random.default_rng(seed)
    xo = rng.uniform(-1, 1, (partners, 2)).astype(dtype)
    if ties:
        xo[rng.integers(0, partners, partners)] = xo[0]  # repeated rows: equal d²
    x = rng.uniform(-1.2, 1.2, (3, 5, 2)).astype(dtype)
    x[0, 0] = xo[-1]  # a point on a partner: d² = 0
    got = [np.empty((3, 5, cand), t) for t in (np.int64, dtype, dtype)]
    point_candidates(x, xo, 7, *got)
    for t, i in np.ndindex(3, 5):
        want = [np.empty(cand, a.dtype) for a in got]
        _nearest(x[t, i, 0], x[t, i, 1], xo, 7, *want)
        for a, b in zip(got, want, strict=True):
            np.testing.assert_array_equal(a[t, i], b)
