"""3-D problem files written from Python objects read back to the same scene: names of any
characters, rotations bit for bit."""

from __future__ import annotations

import numpy as np
from hypothesis import example, given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

import gdnplan as gp
from gdnplan.arm3d import Scene3D, box_obstacle, load_robot3d
from gdnplan.arm3d.write_file3d import problem_file_text

ROBOT = load_robot3d("ur5e")
START = [0.786, 2.496, 1.732, -1.727, -1.256, 2.347]


def _read_back(tmp_path, scene: Scene3D) -> Scene3D:
    path = tmp_path / "written.toml"
    path.write_text(problem_file_text({"name": "ur5e"}, scene, START, START), encoding="utf-8")
    return gp.Problem.from_toml(path).scene


@settings(max_examples=40, deadline=None)
@given(name=st.text(st.characters(exclude_categories=["Cs"]), max_size=12))
@example(name="a\nb")  # a control character was written raw: malformed TOML
@example(name="nul\x00 del\x7f bell\x07")
@example(name='quote" back\\slash\ttab')
def test_obstacle_names_of_any_characters_read_back(tmp_path_factory, name):
    scene = Scene3D(ROBOT, [box_obstacle((0.1, 0.1, 0.1), (1.0, 1.0, 1.0), name=name)])
    assert _read_back(tmp_path_factory.mktemp("w"), scene).obstacles[0].name == name


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 2**32 - 1))
@example(seed=0)
def test_a_rotation_reads_back_bit_for_bit(tmp_path_factory, seed):
    """The reader projected every matrix onto the rotations again (an SVD), moving one written
    from a rotation by ~1e-16: a replanned file was not quite the scene it was written from."""
    rotation = Rotation.random(random_state=seed).as_matrix()
    scene = Scene3D(ROBOT, [box_obstacle((0.1, 0.2, 0.3), (1.0, 1.0, 1.0), rotation)])
    back = _read_back(tmp_path_factory.mktemp("w"), scene).obstacles[0].pose
    np.testing.assert_array_equal(
        np.asarray(back.getRotation()), np.asarray(scene.obstacles[0].pose.getRotation())
    )
