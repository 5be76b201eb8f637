"""The whole-network pass of one-way GraphDistNet (models/graphdistnet/fused_net.py) against
the torch reference path (``fused=False``: autograd through :meth:`GraphDistNet.lean`).

Every shipped weights file the pass serves (one-way soft-kNN: d, e), random and near-contact
configurations, more than one tile. Float64: d̂ and ∂d̂/∂q agree to 1e-9 relative (the same
function up to summation order). Float32 against a float64 truth: the yardstick is the
reference's own float32 error. d̂ agrees with float64 to ~1e-6 m in both (asserted: 2e-6 ·
scale); single gradients do not reach 1e-6 relative in either path, because float32
rounding flips pre-activations within ~1e-7 of a LeakyReLU kink onto the other slope (over
the 40 configurations here, on 2026-12-02, the 90th-percentile relative gradient error was
5.2e-6 / 2.6e-6 whole pass and 7.1e-6 / 6.1e-6 reference on (d) / (e), the worst 1.7e-3 /
2.7e-5 and 1.7e-3 / 5.0e-5; the largest d̂ error 1.2e-6 / 6.1e-7 m and 1.3e-6 / 6.0e-7 m).
Asserted: the whole pass's 90th percentile under 1e-4 and at
most 3× the reference's.
"""

import os

import numpy as np
import pytest
import torch

import gdnplan as gp
from gdnplan.models.graphdistnet import GraphDistNetModel, fused_net
from gdnplan.models.graphdistnet import fused as fused_kernel

SERVED = ("d", "e")  # shipped weights the pass serves (scene of the same name)


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


def configurations(scene: gp.Scene, n: int = 64, near: int = 16) -> np.ndarray:
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
@pytest.mark.parametrize("weights", SERVED)
def test_whole_pass_equals_reference_in_float64(weights):
    scene = gp.make_scene(weights, seed=0)
    q = configurations(scene)
    whole, reference = pair(weights, torch.float64)
    assert whole._graphs(scene).whole is not None  # the pass under test serves this network
    assert len(q) > fused_kernel.TILE_ROWS // (3 * whole._graphs(scene).robot.n_nodes)  # tiles
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
@pytest.mark.parametrize("weights", SERVED)
def test_whole_pass_float32_is_as_accurate_as_the_reference(weights):
    scene = gp.make_scene(weights, seed=1)
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


def test_whole_pass_serves_one_way_networks_only():
    names = {"a": "a", "b": "b", "c": "c", "d": "d", "e": "e", "ur5e": "fetch"}
    served = {w for w in names if fused_net.serves(gp.load_model(w).config)}
    assert served == set(SERVED)
    scene = gp.make_scene("d", seed=0)
    assert gp.load_model("d")._graphs(scene).whole is not None or not fused_kernel.AVAILABLE
    reference = GraphDistNetModel(gp.load_model("d").net, fused=False)
    assert reference._graphs(scene).whole is None
