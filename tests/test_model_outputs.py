"""Weights whose values are finite but overflow the network's arithmetic: refused at load when a
tensor holds a value beyond MAX_WEIGHT, and at every public distance and gradient when the
outputs are NaN or infinite (gdnplan/models/outputs.py). The planner never gets a NaN silently."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
import torch
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st
from safetensors.torch import load_file

import gdnplan as gp
from gdnplan.arm3d import load_robot3d, random_boxes
from gdnplan.assets import weights_file
from gdnplan.errors import InputError
from gdnplan.models.clearancenet import ClearanceNet, ClearanceNetConfig, ClearanceNetModel
from gdnplan.models.clearancenet3d import ClearanceNet3D, ClearanceNet3DConfig, ClearanceNet3DModel
from gdnplan.models.graphdistnet import load_graphdistnet_weights
from gdnplan.models.graphdistnet3d import (
    GraphDistNet3D,
    GraphDistNet3DConfig,
    GraphDistNet3DModel,
    load_graphdistnet3d,
)
from gdnplan.models.outputs import MAX_WEIGHT, finite
from gdnplan.models.weights import read_card, write_weights


def _scaled(tmp: Path, name: str, scale: float, one: float | None = None) -> Path:
    """The shipped weights ``name`` with every tensor × ``scale`` (and, with ``one``, the first
    entry of the first tensor set to it), written as a sealed pair under ``tmp``."""
    src = weights_file(name)
    tensors = {k: v * scale for k, v in load_file(str(src)).items()}
    if one is not None:
        first = next(iter(tensors))
        tensors[first].view(-1)[0] = one
    return write_weights(tmp / f"{name}_{scale:g}_{one}.safetensors", tensors, read_card(src))


@pytest.mark.parametrize("name", ["d", "clearancenet_b", "ur5e_storage3d"])
@pytest.mark.parametrize(("scale", "one"), [(1e30, None), (1.0, 3e38)])
def test_huge_finite_weights_are_refused_at_load(tmp_path, name, scale, one):
    path = _scaled(tmp_path, name, scale, one)
    limit = re.escape(f"{MAX_WEIGHT:g}")
    with pytest.raises(InputError, match=rf"{re.escape(path.name)} tensor .* beyond {limit}"):
        gp.load_model(path)


@settings(
    max_examples=6, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(exponent=st.integers(0, 40), fused=st.sampled_from([None, False]))
@example(exponent=4, fused=None)  # ×1e4: the compiled pass's soft minimum divided by zero
@example(exponent=4, fused=False)  # ×1e4: torch's pass gave NaN for every configuration
@example(exponent=30, fused=None)
def test_planar_graphdistnet_gives_finite_numbers_or_refuses(tmp_path, exponent, fused):
    path = _scaled(tmp_path, "d", 10.0**exponent)
    scene = gp.make_scene("d", seed=1)
    q = scene.robot.sample(20, seed=0)
    try:
        model = load_graphdistnet_weights(path, fused=fused)
        d = model.distance(scene, q)
        d2, g = model.distance_and_grad(scene, q)
        d3, later = model.distance_deferred_grad(scene, q)
        g3 = later()
    except InputError as e:
        assert path.name in str(e)
        return
    for value in (d, d2, g, d3, g3):
        assert np.isfinite(value).all()


def _poisoned(net: torch.nn.Module) -> torch.nn.Module:
    """``net`` with its last parameter's first entry infinite (past any load-time check)."""
    with torch.no_grad():
        list(net.parameters())[-1].view(-1)[0] = float("inf")
    return net


def test_every_learned_model_refuses_non_finite_outputs():
    planar = gp.make_scene("b", seed=0)
    q = planar.robot.sample(3, seed=0)
    config = ClearanceNetConfig.for_env("b", hidden=(8,))
    model = ClearanceNetModel(_poisoned(ClearanceNet(config)))
    for call in (model.distance, model.distance_and_grad):
        with pytest.raises(InputError, match="NaN or infinite distances for 3 of 3"):
            call(planar, q)
    robot = load_robot3d("ur5e")
    scene = random_boxes(robot, 20, seed=0)
    q3 = robot.random_configurations(2, np.random.default_rng(0))
    cn3 = ClearanceNet3DModel(_poisoned(ClearanceNet3D(ClearanceNet3DConfig(hidden=(8,)))))
    net3 = GraphDistNet3D(GraphDistNet3DConfig(scale=1.2, layers=2, hidden=8))
    for fused in (False, None):
        gdn3 = GraphDistNet3DModel(_poisoned(net3), self_collision=False, fused=fused)
        for call in (gdn3.distance, gdn3.distance_and_grad):
            with pytest.raises(InputError, match="NaN or infinite"):
                call(scene, q3)
    for call in (cn3.distance, cn3.distance_and_grad):
        with pytest.raises(InputError, match="NaN or infinite"):
            call(scene, q3)


def test_the_message_names_the_weights_file(tmp_path):
    path = _scaled(tmp_path, "ur5e_storage3d", 1.0)
    model = load_graphdistnet3d(path)
    match = rf"weights {re.escape(str(path))}.* gradients for 1 of 2 .*q\[1\]"
    with pytest.raises(InputError, match=match):
        finite(model, np.zeros(2), np.array([[0.0, 1.0], [np.nan, 0.0]]))
