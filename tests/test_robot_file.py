"""A problem file's own URDF robot: end-to-end plans, relative paths, and one clear error for
every bad ``[robot]`` key or value."""

from __future__ import annotations

import shutil
import subprocess
import sys
import tomllib
from pathlib import Path

import numpy as np
import pytest
import tomli_w
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import gdnplan as gp
from gdnplan.errors import GdnplanError, ProblemFileError, UnknownNameError
from gdnplan.robot_file import URDF_KEYS, robot_from_table, user_robot_name
from gdnplan.scene import scene_from_config

ROOT = Path(__file__).resolve().parent.parent
EXAMPLE = ROOT / "examples" / "three_link_arm.toml"
URDF = ROOT / "examples" / "three_link_arm.urdf"
BASE = tomllib.loads(EXAMPLE.read_text())


def copy_example(folder: Path) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    shutil.copy(URDF, folder / URDF.name)
    shutil.copy(EXAMPLE, folder / EXAMPLE.name)
    return folder / EXAMPLE.name


def robot_table(**changes) -> dict:
    table = {**BASE["robot"], "urdf": str(URDF), **changes}
    return {k: v for k, v in table.items() if v is not None}


def test_example_problem_plans_certified_with_coal():
    problem = gp.Problem.from_toml(EXAMPLE)
    robot = problem.scene.robot
    assert robot.name == "three_link_arm" and robot.joint_names == ["shoulder", "elbow", "wrist"]
    assert any(p.name == "forearm_polygon0" and p.body == 2 for p in robot.polygons)
    result = gp.plan(problem, collision="coal")
    assert result.success and result.min_distance > 0
    np.testing.assert_allclose(result.q[[0, -1]], [problem.start, problem.goal], atol=1e-6)


def test_relative_urdf_resolves_against_the_problem_file(tmp_path, monkeypatch):
    path = copy_example(tmp_path / "elsewhere")
    monkeypatch.chdir(tmp_path)  # not the problem file's folder
    problem = gp.Problem.from_toml(path)
    assert Path(problem.scene.robot.info["urdf"]) == path.parent / "three_link_arm.urdf"
    cfg = tomllib.loads(path.read_text())  # a mapping: relative to the current directory
    with pytest.raises(UnknownNameError, match=r"three_link_arm\.urdf does not exist"):
        gp.Problem.from_config(cfg)
    monkeypatch.chdir(path.parent)
    assert gp.Problem.from_config(cfg).scene.robot.dof == 3


def test_cli_plans_the_example_from_another_directory(tmp_path):
    proc = subprocess.run(
        [sys.executable, "-m", "gdnplan.cli", "plan", str(EXAMPLE), "--collision", "coal"],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert "certified collision-free" in proc.stdout


def test_cli_reports_a_broken_urdf_in_one_line(tmp_path):
    path = copy_example(tmp_path)
    (tmp_path / "three_link_arm.urdf").write_text('<robot name="x"><link name="a"/>')
    proc = subprocess.run(
        [sys.executable, "-m", "gdnplan.cli", "plan", str(path), "--collision", "coal"],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert proc.returncode == 2
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and "urdf" in lines[0] and "Traceback" not in proc.stderr


def test_show_draws_a_urdf_problem(tmp_path):
    from typer.testing import CliRunner

    from gdnplan.cli import app

    out = tmp_path / "arm.png"
    result = CliRunner().invoke(app, ["show", str(EXAMPLE), "--out", str(out)])
    assert result.exit_code == 0, result.output
    assert out.read_bytes()[:4] == b"\x89PNG"


def test_polygons_can_replace_the_collision_geometry():
    robot = robot_from_table(robot_table(collision_geometry=False))
    assert [p.name for p in robot.polygons] == ["forearm_polygon0"]


def test_a_copy_of_a_shipped_urdf_gets_its_own_name(tmp_path):
    shutil.copy(ROOT / "robots" / "planar2.urdf", tmp_path / "planar2.urdf")
    robot = robot_from_table({"urdf": "planar2.urdf", "joints": ["joint1", "joint2"]}, tmp_path)
    assert robot.name == "planar2-urdf" and robot.name not in gp.robot_names()
    assert user_robot_name("", Path("x/my.urdf")) == "my"


def test_urdf_robot_with_a_generated_scene():
    cfg = {"robot": robot_table(), "scene": {"generator": "a"}}
    scene = scene_from_config(cfg)
    assert scene.robot.name == "three_link_arm" and len(scene.obstacles) == 1


@pytest.mark.parametrize(
    ("changes", "error", "message"),
    [
        ({"name": "planar2"}, ProblemFileError, "either name .* or urdf"),
        ({"joint": ["a"]}, ProblemFileError, r"unknown key\(s\) \['joint'\]"),
        ({"gripper": "open"}, ProblemFileError, "unknown key"),
        ({"joints": None}, ProblemFileError, "joints: missing"),
        ({"joints": "shoulder"}, ProblemFileError, "joints: expected a list"),
        ({"joints": []}, ProblemFileError, "joints: expected a list"),
        ({"joints": ["shoulder", "knee"]}, UnknownNameError, "'knee' is not in"),
        ({"joints": ["shoulder", "elbow", "tool_roll"]}, ProblemFileError, "is a planning"),
        (
            {"joints": ["shoulder", "elbow", "tool_roll"], "locked": {}},
            ProblemFileError,
            "'tool_roll' turns about",
        ),
        ({"joints": ["shoulder", "shoulder"]}, ProblemFileError, "twice"),
        ({"urdf": 3}, ProblemFileError, "urdf: expected a file path"),
        ({"urdf": "a\x00b"}, UnknownNameError, "does not exist"),
        ({"urdf": "/"}, UnknownNameError, "does not exist"),
        ({"plane": [[1, 0, 0], [0, 0, 1]]}, ProblemFileError, "'shoulder' turns about"),
        ({"plane": [[1, 0, 0], [2, 0, 0]]}, ProblemFileError, "plane: .*perpendicular"),
        ({"plane": [1, 0, 0]}, ProblemFileError, "plane: expected two 3-vectors"),
        ({"locked": {"tool_roll": "x"}}, ProblemFileError, "locked: expected a table"),
        ({"locked": [1]}, ProblemFileError, "locked: expected a table"),
        ({"locked": {"knee": 1.0}}, UnknownNameError, "locked: joint 'knee'"),
        ({"locked": {"tool_roll": float("nan")}}, ProblemFileError, "finite"),
        ({"locked": {"tool_roll": 2.0}}, ProblemFileError, "outside its limits"),
        ({"package_dirs": "m"}, ProblemFileError, "package_dirs: expected a list"),
        ({"max_vertices": 2}, ProblemFileError, "max_vertices"),
        ({"max_vertices": 3.5}, ProblemFileError, "max_vertices"),
        ({"base_radius": -1}, ProblemFileError, "base_radius"),
        ({"base_radius": "x"}, ProblemFileError, "base_radius"),
        ({"collision_geometry": "yes"}, ProblemFileError, "collision_geometry"),
        ({"polygons": {"link": "tool"}}, ProblemFileError, "expected an array"),
        ({"polygons": [{"link": "tool"}]}, ProblemFileError, "exactly link and polygon"),
        (
            {"polygons": [{"link": 1, "polygon": [[0, 0], [1, 0], [0, 1]]}]},
            ProblemFileError,
            "link: expected a link name",
        ),
        (
            {"polygons": [{"link": "tool", "polygon": [[0, 0], [1, 0]]}]},
            ProblemFileError,
            "at least 3 vertices",
        ),
        (
            {"polygons": [{"link": "tool", "polygon": [[0, 0], [1, 0], [0.2, 0.2], [0, 1]]}]},
            ProblemFileError,
            "not convex",
        ),
        (
            {"polygons": [{"link": "toe", "polygon": [[0, 0], [1, 0], [0, 1]]}]},
            UnknownNameError,
            "frame 'toe' does not exist.*'forearm'",
        ),
        ({"collision_geometry": False, "polygons": []}, ProblemFileError, "no collision geometry"),
    ],
)
def test_bad_robot_tables_are_one_line_errors(changes, error, message):
    with pytest.raises(error, match=message) as info:
        robot_from_table(robot_table(**changes))
    assert str(info.value).startswith("[robot]") or "robot.polygons" in str(info.value)
    assert "\n" not in str(info.value)


def test_huge_plane_axes_are_directions():
    robot = robot_from_table(robot_table(plane=[[1e308, 1e308, 0], [-1e308, 1e308, 0]]))
    np.testing.assert_allclose(
        robot.plane.axes, [[0.5**0.5, 0.5**0.5, 0], [-(0.5**0.5), 0.5**0.5, 0]]
    )


def test_problem_file_errors_name_the_file(tmp_path):
    path = copy_example(tmp_path)
    path.write_text(path.read_text().replace('"wrist"]', '"wrist", "tool_roll"]'))
    with pytest.raises(ProblemFileError, match=f"{path}: .*tool_roll"):
        gp.Problem.from_toml(path)


fuzz_values = st.recursive(
    st.one_of(
        st.integers(-(2**63), 2**63 - 1),
        st.floats(allow_nan=True, allow_infinity=True),
        st.text(max_size=6),
        st.booleans(),
        st.sampled_from(["shoulder", "tool", "forearm", "three_link_arm.urdf", ".", "/"]),
    ),
    lambda inner: st.one_of(
        st.lists(inner, max_size=4),
        st.dictionaries(st.sampled_from(["tool_roll", "link", "polygon", "x"]), inner, max_size=3),
    ),
    max_leaves=10,
)


@settings(max_examples=120, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    changes=st.dictionaries(st.sampled_from(sorted(URDF_KEYS | {"name"})), fuzz_values, max_size=3)
)
def test_any_robot_table_is_a_robot_or_one_gdnplan_error(changes):
    table = {**robot_table(), **changes}
    try:
        tomli_w.dumps({"robot": table})  # only what a TOML file can say
    except (TypeError, ValueError):
        return
    try:
        robot = robot_from_table(table, URDF.parent)
    except GdnplanError as e:
        assert str(e) and "\n" not in str(e).strip()
    else:
        assert robot.dof >= 1 and robot.n_links >= 1
