"""The fused ring messages (models/graphdistnet/fused.py) against the torch reference path.

Every shipped soft-kNN weights file, random and near-contact configurations (coal distance
within a few centimetres): in float64 the two kernels give the same d̂ and ∂d̂/∂q to 1e-9
relative (the same function, up to summation order); in float32 both are as close to the
float64 result as float32 allows (the reference's own float32 error is the yardstick:
rounding flips the sign of pre-activations within ~1e-7 of a LeakyReLU kink, so single
gradients differ by more than 1e-6 relative between any two float32 summation orders).
"""

from pathlib import Path

import numpy as np
import pytest
import torch

import gdnplan as gp
from gdnplan.errors import InputError
from gdnplan.models.graphdistnet import (
    GraphDistNet,
    GraphDistNetConfig,
    GraphDistNetModel,
    load_graphdistnet_weights,
)
from gdnplan.models.graphdistnet import fused as fused_kernel

WEIGHTS = Path(__file__).resolve().parent.parent / "weights"
SHIPPED = {"a": "a", "b": "b", "c": "c", "d": "d", "e": "e", "ur5e": "fetch"}  # weights: scene

pytestmark = pytest.mark.skipif(not fused_kernel.AVAILABLE, reason="numba is not installed")


def configurations(scene: gp.Scene, n: int = 24, near: int = 16) -> np.ndarray:
    """n random configurations and the ``near`` of 400 others closest to contact (coal)."""
    pool = scene.robot.sample(400, seed=7)
    closest = np.argsort(np.abs(gp.signed_distance(scene, pool)))[:near]
    return np.concatenate([scene.robot.sample(n, seed=3), pool[closest]])


def pair(weights: str, dtype: torch.dtype) -> tuple[GraphDistNetModel, GraphDistNetModel]:
    """The fused and the reference model of a shipped weights file, both in ``dtype``."""
    loaded = gp.load_model(WEIGHTS / f"{weights}.safetensors")
    kwargs = {"card": loaded.card, "dtype": dtype, "chunk": 16}  # several chunks, tiles
    return GraphDistNetModel(loaded.net, fused=True, **kwargs), GraphDistNetModel(
        loaded.net, fused=False, **kwargs
    )


@pytest.mark.parametrize("weights", sorted(SHIPPED))
def test_fused_equals_reference_in_float64(weights):
    scene = gp.make_scene(SHIPPED[weights], seed=0)
    q = configurations(scene)
    fused, reference = pair(weights, torch.float64)
    d, g = fused.distance_and_grad(scene, q)
    d_ref, g_ref = reference.distance_and_grad(scene, q)
    assert np.abs(d_ref).min() < 0.05  # near-contact configurations are in the set
    np.testing.assert_allclose(d, d_ref, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(g, g_ref, rtol=1e-9, atol=1e-9 * np.abs(g_ref).max())
    np.testing.assert_allclose(fused.distance(scene, q), d, rtol=1e-12, atol=1e-14)


@pytest.mark.parametrize("weights", ["b", "d", "e"])
def test_fused_float32_is_as_accurate_as_the_reference(weights):
    scene = gp.make_scene(SHIPPED[weights], seed=1)
    q = configurations(scene)
    exact = pair(weights, torch.float64)[1].distance_and_grad(scene, q)
    errors = []
    for model in pair(weights, torch.float32):
        d, g = model.distance_and_grad(scene, q)
        np.testing.assert_allclose(d, exact[0], atol=2e-6 * model.config.scale)
        errors.append(np.abs(g - exact[1]).max(1) / np.abs(exact[1]).max(1))
    fused_err, reference_err = (np.quantile(e, 0.9) for e in errors)
    assert fused_err < 1e-4
    assert fused_err <= 3 * reference_err + 1e-6


def test_fused_setting_resolves_by_network_and_refuses_what_it_cannot_serve(monkeypatch):
    def model(fused=None, **changes) -> GraphDistNetModel:
        return GraphDistNetModel(GraphDistNet(GraphDistNetConfig(**changes)), fused=fused)

    assert model().fused and not model(fused=False).fused
    assert not model(mlp=()).fused  # no hidden layer: nothing to fuse
    assert not model(mlp=(32, 16, 32)).fused  # widths differ
    assert not model(cross="argmax").fused  # the padded reference forward serves it
    with pytest.raises(InputError, match="fused"):
        model(fused=True, mlp=(32, 16))
    assert load_graphdistnet_weights(WEIGHTS / "d.safetensors").fused
    assert not load_graphdistnet_weights(WEIGHTS / "d.safetensors", fused=False).fused
    assert not load_graphdistnet_weights(WEIGHTS / "d_faithful.safetensors").fused  # argmax
    monkeypatch.setattr(fused_kernel, "AVAILABLE", False)
    assert not model().fused
    with pytest.raises(InputError, match="numba is not installed"):
        model(fused=True)


def test_fused_kernel_gradient_matches_finite_differences():
    """∂/∂u and ∂/∂c of the fused messages against central differences (float64)."""
    torch.manual_seed(0)
    b, n, h = 3, 5, 8
    ring = torch.cat([torch.arange(n).roll(1), torch.arange(n).roll(-1)])
    layers = [torch.nn.Linear(h, h).double() for _ in range(2)]
    weights = [t.detach() for m in layers for t in m.parameters()]
    u = torch.randn(b, n, h, dtype=torch.float64, requires_grad=True)
    c = torch.randn(b, n, h, dtype=torch.float64, requires_grad=True)
    torch.autograd.gradcheck(
        lambda u, c: fused_kernel.FusedRingMessages.apply(u, c, ring, *weights), (u, c)
    )
