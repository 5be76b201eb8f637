"""Problem files of the 3-D fetch stages: ordinary 3-D problem files. Every shipped one loads
and is the canonical fetch; written files read back into the same scene, held stick, start and
goal; ``gdnplan plan`` certifies them; a fuzzed ``[robot.held]`` table is one error line."""

from __future__ import annotations

import copy
import math
import tomllib
from pathlib import Path

import numpy as np
import pytest
import tomli_w
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from gdnplan.arm3d import signed_distance3d
from gdnplan.arm3d.fetch3d import MARGIN, PLANNED, STAGE_SOLVERS, WAYPOINTS
from gdnplan.arm3d.fetch3d_files import stage_file_text, write_stage_problems
from gdnplan.arm3d.fetch3d_scene import fetch3d
from gdnplan.arm3d.held import HELD_LINK
from gdnplan.errors import GdnplanError, ProblemFileError
from gdnplan.trajopt import Problem

SHIPPED = Path(__file__).resolve().parent.parent / "problems" / "fetch3d"
BRING_OUT = tomllib.loads((SHIPPED / "fetch3d_bring_out.toml").read_text())


@pytest.fixture(scope="module")
def canonical():
    return fetch3d(0)


def same_scene(a, b) -> None:
    """Two Scene3D are the same: obstacles (names, shapes' sizes, poses), robot shapes (the
    held one included, with its placement), self-collision pairs and distances."""
    assert [o.name for o in a.obstacles] == [o.name for o in b.obstacles]
    for x, y in zip(a.obstacles, b.obstacles, strict=True):
        assert type(x.shape) is type(y.shape)
        np.testing.assert_array_equal(x.shape.halfSide, y.shape.halfSide)  # all boxes here
        np.testing.assert_array_equal(x.pose.getRotation(), y.pose.getRotation())
        np.testing.assert_array_equal(x.pose.getTranslation(), y.pose.getTranslation())
    ra, rb = a.robot, b.robot
    assert [(s.link, s.name, s.body) for s in ra.shapes] == [
        (s.link, s.name, s.body) for s in rb.shapes
    ]
    for s, t in zip(ra.shapes, rb.shapes, strict=True):
        np.testing.assert_allclose(s.placement, t.placement, atol=1e-15)
    np.testing.assert_array_equal(ra.self_pairs, rb.self_pairs)
    q = ra.random_configurations(20, np.random.default_rng(0))
    np.testing.assert_allclose(signed_distance3d(a, q), signed_distance3d(b, q), atol=1e-12)


def test_every_shipped_stage_file_loads_as_the_canonical_stage(canonical):
    assert sorted(p.name for p in SHIPPED.glob("*.toml")) == sorted(
        f"fetch3d_{s}.toml" for s in PLANNED
    )
    for stage, (state, start, goal) in PLANNED.items():
        problem = Problem.from_toml(SHIPPED / f"fetch3d_{stage}.toml")
        same_scene(problem.scene, canonical.scenes[state])
        held = HELD_LINK in problem.scene.robot.links
        assert held == (state == "holding")
        np.testing.assert_allclose(problem.start, canonical.q[start], atol=1e-6)  # IK digits
        np.testing.assert_allclose(problem.goal, canonical.q[goal], atol=1e-6)


def test_written_files_read_back_into_the_same_scene_held_start_and_goal(canonical, tmp_path):
    paths = write_stage_problems(canonical, tmp_path / "out")
    assert [p.name for p in paths] == [f"fetch3d_{s}.toml" for s in PLANNED]
    for (stage, (state, start, goal)), path in zip(PLANNED.items(), paths, strict=True):
        problem = Problem.from_toml(path)
        same_scene(problem.scene, canonical.scenes[state])
        np.testing.assert_array_equal(problem.start, canonical.q[start])
        np.testing.assert_array_equal(problem.goal, canonical.q[goal])
        assert problem.margin == MARGIN and problem.waypoints == WAYPOINTS
        if stage in STAGE_SOLVERS:
            assert problem.solver.seed == STAGE_SOLVERS[stage].seed
        info, built = problem.scene.robot.info, canonical.scenes[state].robot.info
        if state == "holding":
            assert info["held"] == built["held"] and info["tool_frame"] == built["tool_frame"]
            np.testing.assert_array_equal(info["held_placement"], built["held_placement"])


def plan_cli(args: list[str], capsys) -> tuple[int, str, str]:
    from gdnplan.cli import run

    with pytest.raises(SystemExit) as exit_:
        run(["plan", *args])
    out = capsys.readouterr()
    return exit_.value.code or 0, out.out, out.err


@pytest.mark.parametrize(
    "stage",
    [
        "approach",
        "reach_in",
        "bring_out",
        pytest.param("retreat", marks=pytest.mark.slow),  # ~30 s: RRT-Connect and Ipopt
    ],
)
def test_gdnplan_plan_certifies_a_shipped_stage_file(stage, capsys):
    code, out, err = plan_cli([str(SHIPPED / f"fetch3d_{stage}.toml"), "-q"], capsys)
    assert code == 0, err
    assert "certified collision-free" in out


def test_a_stage_text_is_written_only_whole(canonical, tmp_path):
    """A directory that is a file is refused before anything is written."""
    target = tmp_path / "a_file"
    target.write_text("x")
    with pytest.raises(GdnplanError):
        write_stage_problems(canonical, target)
    assert sorted(tmp_path.iterdir()) == [target] and target.read_text() == "x"


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (lambda h: h.update(type="cone"), r"\[robot.held\] type"),
        (lambda h: h.pop("size"), r"\[robot.held\] size: missing"),
        (lambda h: h.update(size=[0.03, -0.03, 0.25]), r"\[robot.held\] \(stick\)"),
        (lambda h: h.update(matrix=[[1, 0, 0], [0, 1, 0], [0, 0, -1]]), "not a rotation"),
        (lambda h: h.update(quaternion=[0, 0, 0, 0]), "zero length"),
        (lambda h: h.update(rpy=[0, 0]), r"\[robot.held\] rpy"),
        (lambda h: h.update(frame="nowhere"), "not a frame of ur5e"),
        (lambda h: h.update(position=[0.0, 0.0, math.nan]), r"\[robot.held\]"),
        (lambda h: h.update(colour="red"), "colour"),
    ],
)
def test_bad_held_tables_are_one_error_naming_them(change, message):
    cfg = copy.deepcopy(BRING_OUT)
    change(cfg["robot"]["held"])
    with pytest.raises(ProblemFileError, match=message) as info:
        Problem.from_config(cfg)
    assert "\n" not in str(info.value)


def test_finger_is_for_built_in_grippers_only():
    cfg = copy.deepcopy(BRING_OUT)
    cfg["robot"]["finger"] = 0.2
    with pytest.raises(ProblemFileError, match=r"\[robot\] finger: expected"):
        Problem.from_config(cfg)
    cfg["robot"].update(name="ur5", finger=0.01)
    with pytest.raises(ProblemFileError, match=r"\[robot\] finger: only for"):
        Problem.from_config(cfg)


numbers = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True),
    st.sampled_from([0, -1, 1e-9, 1e9, math.nan, math.inf, 0.03]),
    st.text(max_size=4),
    st.booleans(),
)
matrices = st.lists(st.lists(st.floats(-2, 2), min_size=3, max_size=3), min_size=3, max_size=3)
HELD_FIELDS = {
    "type": st.sampled_from(["box", "sphere", "cylinder", "capsule", "convex", "mesh", "x"]),
    "size": st.lists(numbers, max_size=4),
    "radius": numbers,
    "length": numbers,
    "points": st.lists(st.lists(numbers, max_size=3), max_size=5),
    "position": st.lists(numbers | st.floats(-0.2, 0.2), max_size=4),
    "quaternion": st.lists(numbers, max_size=5),
    "rpy": st.lists(numbers, max_size=4),
    "matrix": matrices | st.lists(numbers, max_size=3),
    "frame": numbers | st.sampled_from(["gripper_tcp", "tool0", "nope"]),
    "name": numbers,
}


@st.composite
def held_tables(draw) -> dict:
    held = dict(BRING_OUT["robot"]["held"])
    for key in draw(st.lists(st.sampled_from(sorted(HELD_FIELDS)), min_size=1, max_size=3)):
        held[key] = draw(HELD_FIELDS[key])
    if draw(st.booleans()):
        held.pop(draw(st.sampled_from(sorted(held))))
    return held


def is_rotation(m) -> bool:
    a = np.asarray(m, float)
    return a.shape == (3, 3) and np.allclose(a @ a.T, np.eye(3), atol=1e-6) and np.linalg.det(a) > 0


def cli_answer(cfg: dict, folder: Path, json: bool) -> tuple[int, list[str], str, list]:
    """(exit code, stderr lines, stdout, files after) of ``gdnplan plan`` on ``cfg``."""
    import contextlib
    import io

    from gdnplan.cli import run

    path = folder / "p.toml"
    path.write_text(tomli_w.dumps(cfg))
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        with pytest.raises(SystemExit) as exit_:
            run(["plan", str(path), *(["--json"] if json else [])])
    lines = err.getvalue().strip().splitlines()
    return exit_.value.code, lines, out.getvalue(), sorted(folder.iterdir())


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(held=held_tables(), json=st.booleans())
def test_the_cli_answers_a_bad_held_table_in_one_line_exit_2_writing_nothing(
    tmp_path_factory, held, json
):
    cfg = copy.deepcopy(BRING_OUT)
    cfg["robot"]["held"] = held
    try:
        cfg = tomllib.loads(tomli_w.dumps(cfg))
        Problem.from_config(cfg)
    except ProblemFileError:
        pass
    except (TypeError, ValueError, GdnplanError):
        return  # not writable as TOML, or a well-formed table (a start in collision, say)
    else:
        return  # a valid held object: planning it is another test's business
    folder = tmp_path_factory.mktemp("held")
    code, lines, out, after = cli_answer(cfg, folder, json)
    assert code == 2 and len(lines) == 1 and lines[0].startswith("error: "), lines
    assert "[robot" in lines[0]  # names [robot.held] (or [robot] for a bad frame)
    assert out == "" and after == [folder / "p.toml"]


@settings(max_examples=15, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(matrix=matrices.filter(lambda m: not is_rotation(m)), json=st.booleans())
def test_the_cli_refuses_a_held_non_rotation_in_one_line_exit_2_writing_nothing(
    tmp_path_factory, matrix, json
):
    import contextlib
    import io

    from gdnplan.cli import run

    folder = tmp_path_factory.mktemp("held")
    cfg = copy.deepcopy(BRING_OUT)
    cfg["robot"]["held"]["matrix"] = matrix
    path = folder / "p.toml"
    path.write_text(tomli_w.dumps(cfg))
    before = sorted(folder.iterdir())
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        with pytest.raises(SystemExit) as exit_:
            run(["plan", str(path), *(["--json"] if json else [])])
    lines = err.getvalue().strip().splitlines()
    assert exit_.value.code == 2, err.getvalue()
    assert len(lines) == 1 and lines[0].startswith("error: "), err.getvalue()
    assert "[robot.held]" in lines[0] and "not a rotation matrix" in lines[0]
    assert out.getvalue() == "" and sorted(folder.iterdir()) == before


def test_the_stage_text_names_its_stage(canonical):
    text = stage_file_text(canonical, "bring_out")
    assert "stage bring_out" in text and "[robot.held]" in text and "[seed]" in text
    assert "[robot.held]" not in stage_file_text(canonical, "approach")
