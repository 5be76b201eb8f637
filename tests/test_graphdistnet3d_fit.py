"""GraphDistNet-3D weights refuse scenes outside their training (one InputError naming the
obstacle or the robot and the fix), accept the scenes they were trained on, and planar weights
refuse 3-D scenes; the CLI turns a refusal into one line and exit 2."""

from __future__ import annotations

import subprocess
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from gdnplan.arm3d import (
    Robot3D,
    Scene3D,
    box_obstacle,
    cloud_obstacle,
    hold,
    load_robot3d,
    random_boxes,
    sphere_obstacle,
)
from gdnplan.arm3d.builtin import ur5e3d
from gdnplan.arm3d.fetch3d_scene import CANONICAL_STORAGE, OPEN_FINGER
from gdnplan.arm3d.held import stick
from gdnplan.arm3d.problem3d import reaching_problems
from gdnplan.arm3d.storage3d import Placement, storage_obstacles, table_obstacle
from gdnplan.errors import InputError
from gdnplan.models import load_model
from gdnplan.models.graphdistnet3d import GraphDistNet3D, GraphDistNet3DConfig, GraphDistNet3DModel
from gdnplan.trajopt.planner import resolve_model

ROOT = Path(__file__).parents[1]
WEIGHTS = "ur5e_boxes3d_preliminary"


@pytest.fixture(scope="module")
def model():
    return load_model(WEIGHTS)


def ur5e_among(*obstacles) -> Scene3D:
    return Scene3D(
        load_robot3d("ur5e"), [box_obstacle([0.1, 0.1, 0.1], [0.6, 0.0, 0.3]), *obstacles]
    )


def test_the_training_scenes_and_the_reaching_problems_are_accepted(model):
    robot = load_robot3d("ur5e")
    for seed in range(3):
        model.check_scene(random_boxes(robot, 20, seed=seed))
    for problem in reaching_problems("ur5e", n=3, seed=0):
        assert resolve_model("graphdistnet", problem.scene, WEIGHTS).card == model.card
    model.check_scene(ur5e_among(box_obstacle([0.2, 0.05, 0.1], [0.0, -0.5, 0.4])))


@pytest.mark.parametrize(
    ("obstacle", "why"),
    [
        (table_obstacle(), r"\('table'\) is a box of sides 0\.95 × 1\.6 × 0\.05 m"),
        (sphere_obstacle(0.05, [0.5, 0.2, 0.3], name="ball"), r"\('ball'\) is a sphere"),
        (
            box_obstacle([0.1] * 3, [0.5, 0.0, 0.3], np.eye(3)[[1, 2, 0]], name="turned"),
            "",  # a permutation of the axes is still axis-aligned: accepted
        ),
        (
            box_obstacle(
                [0.1] * 3, [0.5, 0.0, 0.3], [[0.8, -0.6, 0], [0.6, 0.8, 0], [0, 0, 1]], "r"
            ),
            r"\('r'\) is a rotated box",
        ),
        (box_obstacle([0.1] * 3, [0.1, 0.1, 0.6], name="near"), r"\('near'\) has its centre 0\.14"),
        (box_obstacle([0.01] * 3, [0.5, 0.0, 0.3], name="tiny"), r"\('tiny'\) is a box of sides"),
    ],
)
def test_obstacles_outside_the_training_boxes_are_refused(model, obstacle, why):
    scene = ur5e_among(obstacle)
    if not why:
        model.check_scene(scene)
        return
    with pytest.raises(InputError, match=r"scene\.obstacles\[1\] " + why) as e:
        model.check_scene(scene)
    assert "axis-aligned boxes with sides 0.05–0.2 m" in str(e.value)
    assert "collision='coal'" in str(e.value) and "\n" not in str(e.value)


def test_the_storage_and_a_point_cloud_are_refused(model):
    storage = Scene3D(
        load_robot3d("ur5e"), storage_obstacles(CANONICAL_STORAGE, Placement(0.62, -0.2, 0.0))
    )
    with pytest.raises(InputError, match=r"scene\.obstacles\[0\] \('storage_\w+'\) is a box"):
        model.check_scene(storage)
    rng = np.random.default_rng(0)
    cloud = cloud_obstacle(rng.uniform([0.4, -0.2, 0.2], [0.6, 0.2, 0.4], (200, 3)), 0.03)
    with pytest.raises(InputError, match=r"is a point cloud \(octree\)"):
        resolve_model("graphdistnet", Scene3D(load_robot3d("ur5e"), [cloud]), WEIGHTS)


def test_another_robot_or_its_changed_geometry_is_refused(model):
    boxes = random_boxes(load_robot3d("ur5e"), 5, seed=0).obstacles
    with pytest.raises(InputError, match="trained for robot 'ur5e', not 'panda'"):
        model.check_scene(Scene3D(load_robot3d("panda"), boxes))
    model.check_scene(Scene3D(ur5e3d(finger=OPEN_FINGER), boxes))  # fingers open: same shapes
    ur5e = load_robot3d("ur5e")
    placement = ur5e.shapes[0].placement.copy()
    placement[:3, 3] += [0.0, 0.0, 0.04]  # one link shape 4 cm off: more than any finger moves
    shapes = (replace(ur5e.shapes[0], placement=placement), *ur5e.shapes[1:])
    moved = Robot3D("ur5e", ur5e.model, shapes, ur5e.self_pairs, {}, {})
    with pytest.raises(InputError, match=r"other link geometry: link nodes moved up to 0\.04 m\)"):
        model.check_scene(Scene3D(moved, boxes))
    held = hold(load_robot3d("ur5e"), *stick(0.3, 0.03))
    with pytest.raises(InputError, match=r"it holds 'stick': 240 graph nodes against 232"):
        model.check_scene(Scene3D(held, boxes))


def test_cards_decide_what_is_checked():
    net = GraphDistNet3D(GraphDistNet3DConfig())
    scene = ur5e_among(sphere_obstacle(0.05, [0.5, 0.2, 0.3]))
    GraphDistNet3DModel(net, card={}).check_scene(scene)  # no training claim: not checked
    GraphDistNet3DModel(net, card={"robot": "ur5e"}).check_scene(scene)
    with pytest.raises(InputError, match="environment 'ur5e_shelves' is not one whose scenes"):
        GraphDistNet3DModel(net, card={"env": "ur5e_shelves"}).check_scene(scene)
    with pytest.raises(InputError, match="needs at least one obstacle"):
        GraphDistNet3DModel(net).check_scene(Scene3D(load_robot3d("ur5e"), []))


def test_planar_weights_refuse_a_3d_scene():
    scene = random_boxes(load_robot3d("ur5e"), 5, seed=0)
    with pytest.raises(InputError, match="weights of environment 'ur5e' are planar and this is a"):
        resolve_model("graphdistnet", scene, "ur5e")  # same robot name: accepted before


def test_the_cli_refuses_a_cloud_with_one_line_and_exit_2():
    run = subprocess.run(
        [
            sys.executable, "-c", "from gdnplan.cli import main; main()", "plan",
            "problems/ur5e_cloud3d.toml", "--collision", "graphdistnet", "--weights", WEIGHTS,
        ],
        capture_output=True, text=True, cwd=ROOT, timeout=300,
    )  # fmt: skip
    assert run.returncode == 2, run.stderr
    lines = [x for x in run.stderr.splitlines() if x.strip()]
    assert len(lines) == 1 and "('wall_scan') is a point cloud (octree)" in lines[0], run.stderr
