"""docs/problem_file_3d.md lists exactly the keys the 3-D parser accepts, and its example loads."""

import re
import tomllib
from pathlib import Path

import pytest

from gdnplan.arm3d.robot_file3d import HELD_FRAME_KEY
from gdnplan.arm3d.scene_file3d import (
    OBSTACLE3D_KEYS,
    POSE_KEYS,
    ROBOT3D_KEYS,
    ROTATION_KEYS,
    SCENE3D_KEYS,
)
from gdnplan.trajopt import Problem

DOC = (Path(__file__).resolve().parent.parent / "docs" / "problem_file_3d.md").read_text()


def section(title: str) -> str:
    start = DOC.index(f"## `{title}`")
    end = DOC.find("\n## ", start + 1)
    return DOC[start : end if end > 0 else None]


def keys_of(text: str) -> set[str]:
    """The first-column keys of the markdown table rows in ``text``."""
    return set(re.findall(r"^\| `(\w+)` \|", text, flags=re.M))


def test_robot_keys_are_documented():
    assert keys_of(section("[robot]")) == set(ROBOT3D_KEYS)


def test_held_keys_are_documented():
    """[robot.held]: a posed solid shape's keys (as an obstacle's, no cloud) plus its frame."""
    text = section("[robot.held]")
    own = set().union(*(keys for kind, keys in OBSTACLE3D_KEYS.items() if kind != "cloud"))
    assert keys_of(text) == (set(POSE_KEYS) - set(ROTATION_KEYS)) | own | {HELD_FRAME_KEY}


def test_scene3d_keys_are_documented():
    assert keys_of(section("[scene3d]")) == set(SCENE3D_KEYS)


def test_obstacle_keys_and_rotations_are_documented():
    text = section("[[scene3d.obstacles]]")
    own = set().union(*OBSTACLE3D_KEYS.values())
    assert keys_of(text) == (set(POSE_KEYS) - set(ROTATION_KEYS)) | own
    for key in ROTATION_KEYS:
        assert f"`{key} =" in text
    for kind in OBSTACLE3D_KEYS:
        assert f"`{kind}`" in text


@pytest.mark.slow  # ~8 s: the Panda's meshes and the pose goal's IK
def test_the_example_loads():
    example = DOC.split("```toml\n", 1)[1].split("```", 1)[0]
    problem = Problem.from_config(tomllib.loads(example))
    assert problem.scene.robot.name == "panda" and len(problem.scene.obstacles) == 21
