"""Problem files of the 3-D fetch stages: written, read back into the same problems, the
shipped ones solve, bad fields are one-line errors naming them."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from gdnplan.arm3d.fetch3d import PLANNED, stage_problems
from gdnplan.arm3d.fetch3d_files import read_stage_problems, stage_file_text, write_stage_problems
from gdnplan.arm3d.fetch3d_scene import fetch3d
from gdnplan.errors import ProblemFileError
from gdnplan.trajopt import plan

SHIPPED = Path(__file__).resolve().parent.parent / "problems" / "fetch3d"


@pytest.fixture(scope="module")
def canonical():
    return fetch3d(0)


def test_written_files_read_back_into_the_stage_problems(canonical, tmp_path):
    paths = write_stage_problems(canonical, tmp_path / "out")
    assert [p.name for p in paths] == [f"fetch3d_{s}.toml" for s in PLANNED]
    for stage, path in zip(PLANNED, paths, strict=True):
        read = read_stage_problems(path)
        built = stage_problems(canonical, stage)
        assert len(read) == len(built)
        for a, b in zip(read, built, strict=True):
            np.testing.assert_array_equal(a.start, b.start)
            np.testing.assert_array_equal(a.goal, b.goal)
            assert a.margin == b.margin and a.waypoints == b.waypoints
            assert a.solver == b.solver
            assert len(a.scene.obstacles) == len(b.scene.obstacles)
            assert a.scene.robot.links == b.scene.robot.links


def test_the_shipped_files_are_the_canonical_fetch(canonical):
    for stage in PLANNED:
        shipped = read_stage_problems(SHIPPED / f"fetch3d_{stage}.toml")
        for a, b in zip(shipped, stage_problems(canonical, stage), strict=True):
            assert np.allclose(a.start, b.start, atol=1e-6)  # IK's last digits may differ
            assert np.allclose(a.goal, b.goal, atol=1e-6)


def test_a_shipped_stage_file_solves_certified():
    (problem,) = read_stage_problems(SHIPPED / "fetch3d_approach.toml")
    result = plan(problem, collision="coal")
    assert result.success and result.min_distance > problem.margin


@pytest.mark.parametrize(
    ("old", "new", "message"),
    [
        ('stage = "approach"', 'stage = "fly"', "stage"),
        ('gripper = "open"', 'gripper = "holding"', "gripper"),
        ("placement = [", "placement = [1e9, ", "placement"),
        ("depth = ", "depth = -", "depth"),
        ("[start]\nq = [", "[start]\nq = [1.0, ", r"\[start\] q"),
        ("waypoints = 30", "waypoints = 1", "waypoints"),
        ("[options]", "[options]\nbogus = 1", "bogus"),
    ],
)
def test_bad_fields_are_one_line_errors_naming_them(canonical, tmp_path, old, new, message):
    text = stage_file_text(canonical, "approach")
    assert old in text
    path = tmp_path / "bad.toml"
    path.write_text(text.replace(old, new, 1))
    with pytest.raises(ProblemFileError, match=message) as info:
        read_stage_problems(path)
    assert "\n" not in str(info.value)
