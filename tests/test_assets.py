"""Shipped files by name, default weights by robot and obstacles, outputs outside the install."""

from __future__ import annotations

import shutil
import subprocess
import sys
import zipfile
from importlib.metadata import version
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from typer.testing import CliRunner

import gdnplan as gp
from gdnplan import assets
from gdnplan.cli import app
from gdnplan.geometry import square
from gdnplan.robot import load_robot
from gdnplan.trajopt import resolve_model

ROOT = Path(__file__).resolve().parent.parent
runner = CliRunner()


def test_shipped_names_cover_the_shipped_folder():
    assert "fetch_reach" in assets.problem_names()
    assert {"a", "b", "c", "d", "e", "ur5e"} <= set(assets.weights_names())
    for name in assets.weights_names():
        assert assets.weights_file(name).with_suffix(".json").is_file(), name


@pytest.mark.parametrize("name", assets.problem_names())
def test_every_shipped_problem_loads_by_name(name):
    problem = gp.Problem.from_toml(name)
    assert problem.scene.robot.dof == len(problem.start)


def test_repository_folders_are_links_into_the_package():
    """One copy of each file in git: robots/, problems/, weights/ point into gdnplan/shipped."""
    for link, target in [
        (ROOT / "problems", assets.PROBLEMS_DIR),
        (ROOT / "weights", assets.WEIGHTS_DIR),
        *((ROOT / "robots" / f"{r}.urdf", assets.robot_urdf(r)) for r in ("planar2", "ur5e")),
    ]:
        assert link.is_symlink(), link
        assert link.resolve() == target.resolve()


def test_a_name_and_its_path_load_the_same_model():
    scene = gp.make_scene("d", seed=4)
    q = scene.robot.sample(5, seed=1)
    by_name = gp.load_model("d").distance(scene, q)
    by_path = gp.load_model(assets.WEIGHTS_DIR / "d.safetensors").distance(scene, q)
    np.testing.assert_array_equal(by_name, by_path)


@pytest.mark.parametrize("ref", ["nosuch", "D", "d_", ""])
def test_unknown_weights_name_lists_the_names(ref):
    with pytest.raises(gp.UnknownNameError, match="choose one of"):
        gp.load_model(ref)


@pytest.mark.parametrize(
    ("load", "ref", "close"),
    [
        (lambda r: gp.load_model(r), "clearancenet_f", "clearancenet_e"),
        (lambda r: gp.Problem.from_toml(r), "fetch_reahc", "fetch_reach"),
        (lambda r: gp.make_scene(r), "fech", "fetch"),
        (lambda r: gp.load_robot(r), "planar8", "planar7"),
        (lambda r: gp.arm3d.load_robot3d(r), "pand", "panda"),
    ],
)
def test_a_misspelt_name_gets_the_closest_one(load, ref, close):
    with pytest.raises(gp.UnknownNameError, match=rf"'{ref}' \(did you mean '{close}'\?\); choose"):
        load(ref)
    with pytest.raises(gp.UnknownNameError) as e:
        load("qqqqqqqqqqqq")
    assert "did you mean" not in str(e.value)


def test_a_card_given_for_its_weights_names_the_weights_file():
    """It was read as a tensors file: 'card a.json does not belong to a.json'."""
    with pytest.raises(gp.InputError, match=r"a\.json is a card; give the weights file beside it"):
        gp.load_model(assets.WEIGHTS_DIR / "a.json")


def test_a_path_is_never_taken_for_a_name(tmp_path):
    with pytest.raises(gp.GdnplanError, match="does not exist"):
        gp.load_model(tmp_path / "d.safetensors")
    assert assets.weights_file("sub/d") == Path("sub/d")
    assert assets.problem_file("x.toml") == Path("x.toml")


def _scene(robot: str, polygons) -> gp.Scene:
    return gp.Scene(load_robot(robot), tuple(polygons))


NON_CONVEX = np.array([[1, 1], [1.4, 1], [1.4, 1.4], [1.3, 1.4], [1.3, 1.1], [1, 1.1]])


@pytest.mark.parametrize(
    ("scene", "expected"),
    [
        (lambda: gp.make_scene("a"), "a"),
        (lambda: gp.make_scene("b", seed=7), "b"),
        (lambda: gp.make_scene("c"), "c"),
        (lambda: gp.make_scene("d", seed=7), "d"),
        (lambda: gp.make_scene("e", seed=7), "e"),
        (lambda: gp.make_scene("fetch"), "ur5e"),
        (lambda: _scene("planar2", [square((0.7, 0.2), 0.2)]), "b"),
        (lambda: _scene("planar7", [square((1.0, 1.0), 0.3)]), "d"),
        (lambda: _scene("planar7", [NON_CONVEX]), "e"),
        (lambda: _scene("ur5e", [square((0.5, 0.5), 0.1)]), "ur5e"),
        # the fixed layout of (a) with one more obstacle is not (a) any more
        (lambda: gp.make_scene("a").with_obstacles([square((0.6, 0.45), 0.3), NON_CONVEX]), "b"),
    ],
)
def test_default_weights_follow_robot_and_obstacles(scene, expected):
    assert assets.default_weights(scene()) == expected


def test_a_robot_without_shipped_weights_is_refused_by_name():
    scene = _scene("ur5", [square((0.5, 0.5), 0.1)])
    with pytest.raises(gp.UnknownNameError, match=r"'ur5'.*gdnplan train"):
        assets.default_weights(scene)


@settings(max_examples=25, deadline=None)
@given(
    robot=st.sampled_from(["planar2", "planar7", "ur5e"]),
    centres=st.lists(st.tuples(st.floats(-2, 2), st.floats(-2, 2)), min_size=1, max_size=4),
    size=st.floats(0.05, 0.4),
    angle=st.floats(0, np.pi / 2),
)
def test_default_weights_always_fit_the_robot(robot, centres, size, angle):
    """Any user scene of a shipped robot gets weights that accept it (never another robot's)."""
    rob = load_robot(robot)
    polys = [square(c, size, angle) for c in centres]
    polys = [
        p for p in polys if np.min(np.linalg.norm(p - rob.chain.joint_origins[0], axis=1)) > 0.3
    ]
    if not polys:
        return
    scene = gp.Scene(rob, tuple(polys))
    model = resolve_model("graphdistnet", scene, None)
    assert np.isfinite(model.distance(scene, rob.sample(2, seed=0))).all()


def test_cli_plans_a_shipped_problem_by_name():
    result = runner.invoke(app, ["plan", "planar2_square", "--collision", "coal"])
    assert result.exit_code == 0, result.output
    assert "planar2_square: certified collision-free" in result.output


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["plan", "no_such_problem"], "no shipped problem named 'no_such_problem'"),
        (["plan", "planar2_square", "--weights", "nosuch"], "no shipped weights named 'nosuch'"),
        (["plan", "planar2_square", "--weights", "d"], "trained for the planar7 robot"),
    ],
)
def test_cli_bad_names_are_one_line_and_exit_2(args, message, capsys):
    from gdnplan.cli import run

    with pytest.raises(SystemExit) as exit_:
        run(args)
    lines = capsys.readouterr().err.strip().splitlines()
    assert exit_.value.code == 2
    assert len(lines) == 1 and lines[0].startswith("error: ") and message in lines[0], lines


def test_version():
    result = runner.invoke(app, ["--version"])
    assert result.exit_code == 0
    assert result.output.strip() == f"gdnplan {version('gdnplan')}"


def test_default_outputs_are_relative_to_the_working_directory(tmp_path, monkeypatch):
    """``generate`` writes under ./data of the caller, never next to the installed package."""
    monkeypatch.chdir(tmp_path)
    result = runner.invoke(
        app, ["generate", "--env", "a", "--split", "test", "--n", "20", "--workers", "1"]
    )
    assert result.exit_code == 0, result.output
    assert any((tmp_path / "data" / "a" / "test").iterdir())
    from gdnplan import data, train

    for default in (data.DATA_DIR, train.OUT_DIR, train.RUNS_DIR):
        assert not default.is_absolute()


def test_wheel_holds_every_shipped_file(tmp_path):
    """The wheel's package data globs cover every file git ships under gdnplan/shipped/."""
    source = tmp_path / "src"  # a copy: building in the checkout would leave build/ there
    shutil.copytree(ROOT / "gdnplan", source / "gdnplan", ignore=shutil.ignore_patterns("__py*"))
    for name in ("pyproject.toml", "README.md", "LICENSE"):
        shutil.copy(ROOT / name, source / name)
    subprocess.run(
        [sys.executable, "-m", "pip", "wheel", "-q", "--no-deps", "-w", str(tmp_path), str(source)],
        check=True,
        capture_output=True,
        timeout=600,
    )
    (wheel,) = tmp_path.glob("gdnplan-*.whl")
    inside = {n for n in zipfile.ZipFile(wheel).namelist() if n.startswith("gdnplan/shipped/")}
    shipped = {
        str(p.relative_to(ROOT))
        for p in (ROOT / "gdnplan" / "shipped").rglob("*")
        if p.is_file() and "__pycache__" not in p.parts
    }
    assert shipped and shipped <= inside


@pytest.mark.parametrize("ref", [None, 3, 1.5, b"d", ["d"]])
@pytest.mark.parametrize("load", [gp.load_model, gp.Problem.from_toml])
def test_a_reference_that_is_neither_name_nor_path_is_an_input_error(load, ref):
    with pytest.raises(gp.InputError, match=r"expected a shipped .* name or a file path"):
        load(ref)
