"""Weights of ``ur5e_storage`` accept the fetch's scenes (fingers open; holding the stick) and
refuse what that environment never drew; the 3-D fetch takes such a model and refuses others."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from gdnplan.arm3d import Scene3D, box_obstacle, sphere_obstacle
from gdnplan.arm3d.builtin import ur5e3d
from gdnplan.arm3d.fetch3d import run_fetch3d
from gdnplan.arm3d.fetch3d_scene import (
    CANONICAL_PLACEMENT,
    CANONICAL_STORAGE,
    fetch3d,
    fetch3d_scenes,
)
from gdnplan.arm3d.held import hold, stick
from gdnplan.arm3d.shapes import box
from gdnplan.errors import InputError
from gdnplan.models.graphdistnet3d import GraphDistNet3D, GraphDistNet3DConfig
from gdnplan.models.graphdistnet3d.model import GraphDistNet3DModel


def _model(env: str) -> GraphDistNet3DModel:
    torch.manual_seed(0)
    net = GraphDistNet3D(GraphDistNet3DConfig(scale=1.2))
    return GraphDistNet3DModel(net, {"env": env, "robot": "ur5e"}, threads=1, fused=False)


@pytest.fixture(scope="module")
def scenes():
    return fetch3d_scenes(CANONICAL_STORAGE, CANONICAL_PLACEMENT)


def test_storage_weights_accept_both_fetch_scenes_and_boxes_weights_refuse_them(scenes):
    storage, boxes = _model("ur5e_storage"), _model("ur5e_boxes")
    for scene in scenes.values():
        storage.check_scene(scene)
        d = storage.distance(scene, np.zeros((2, 6)))
        assert d.shape == (2,) and np.isfinite(d).all()
        with pytest.raises(InputError):
            boxes.check_scene(scene)


@pytest.mark.parametrize(
    ("make", "why"),
    [
        (lambda s: [*s.obstacles, sphere_obstacle(0.05, (0.6, 0.3, 0.3))], "sphere"),
        (
            lambda s: [*s.obstacles, box_obstacle((0.1, 0.1, 0.1), (0.6, 0.3, 0.3), _tilt())],
            "tilted",
        ),
        (lambda s: [*s.obstacles, box_obstacle((0.1, 0.1, 0.1), (0.1, 0.0, 0.3))], "base axis"),
        (lambda s: [*s.obstacles, box_obstacle((2.5, 0.1, 0.1), (0.6, 0.3, 0.3))], "sides"),
    ],
)
def test_obstacles_the_storage_never_drew_are_refused(scenes, make, why):
    scene = Scene3D(scenes["open"].robot, make(scenes["open"]))
    with pytest.raises(InputError, match=why):
        _model("ur5e_storage").check_scene(scene)


def _tilt() -> np.ndarray:
    c, s = np.cos(0.3), np.sin(0.3)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


@pytest.mark.parametrize(
    "held",
    [
        lambda: stick(0.5, 0.03),  # longer than any drawn stick
        lambda: (box((0.1, 0.1, 0.1), "cube"), np.eye(4)),  # a cube
    ],
)
def test_held_objects_outside_the_sticks_are_refused(scenes, held):
    robot = hold(ur5e3d(finger=0.015), *held())
    with pytest.raises(InputError, match="held"):
        _model("ur5e_storage").check_scene(Scene3D(robot, list(scenes["holding"].obstacles)))


def test_the_fetch_checks_a_model_on_both_scenes_before_planning():
    fetch = fetch3d(0)
    with pytest.raises(InputError, match="ur5e_boxes"):
        run_fetch3d(fetch=fetch, collision=_model("ur5e_boxes"))


def test_the_fetch_command_loads_storage_weights_and_refuses_others(tmp_path):
    from gdnplan.cli.fetch3d import NOT_STORAGE, learned_fetch_model
    from gdnplan.models.weights import write_weights

    model = _model("ur5e_storage")
    card = {"model": "graphdistnet3d", "env": "ur5e_storage", "robot": "ur5e"}
    card["config"] = model.config.to_dict()
    path = tmp_path / "storage.safetensors"
    write_weights(path, model.net.state_dict(), card)
    loaded = learned_fetch_model(str(path))
    assert loaded.card["env"] == "ur5e_storage"
    for scene in fetch3d_scenes(CANONICAL_STORAGE, CANONICAL_PLACEMENT).values():
        loaded.check_scene(scene)
    with pytest.raises(InputError, match="ur5e_boxes"):
        learned_fetch_model("ur5e_boxes3d_preliminary")
    with pytest.raises(InputError) as e:
        learned_fetch_model(None)
    assert str(e.value) == NOT_STORAGE
    assert "--weights ur5e_storage3d" in NOT_STORAGE  # the shipped weights that fit, named
