"""The fetch scene: storage with an entrance, stick, free grasp/lift/home/out configurations."""

import tomllib
from pathlib import Path

import numpy as np
import pytest
from shapely.geometry import Point, Polygon, box

import gdnplan as gp
from gdnplan import ur5e as U
from gdnplan.geometry import is_convex
from gdnplan.scene import scene_from_config

PROBLEMS = Path(__file__).resolve().parent.parent / "problems"
CONFIGS = ("q_grasp", "q_lift", "q_home", "q_out", "q_pregrasp")


def polygon(robot, q, name):
    return robot.link_polygons(q)[[p.name for p in robot.polygons].index(name)]


def check_fetch(seed: int) -> None:
    """Every stated property of a fetch scene, checked with coal and shapely."""
    scene = gp.make_scene("fetch", seed=seed)
    held = gp.make_scene("fetch", seed=seed, gripper="holding")
    info, layout = scene.info, scene.info["layout"]
    stick = info["stick"]
    # obstacles: table, storage (non-convex, open at the entrance), stick while not held
    assert len(scene.obstacles) == 3 and np.allclose(scene.obstacles[2], stick)
    assert len(held.obstacles) == 2 and held.robot.info["gripper"] == "holding"
    assert held.robot.info["stick_length"] == layout.stick_length
    storage = Polygon(info["storage"])
    assert storage.is_valid and not is_convex(info["storage"])
    front, e0, e1 = info["entrance"]
    assert not storage.contains(Point(front + layout.wall / 2, (e0 + e1) / 2))  # the opening
    assert storage.contains(Point(front + layout.wall / 2, e1 + 0.005))  # front wall above it
    assert Polygon(stick).distance(storage) == pytest.approx(0.0, abs=1e-12)  # lies on its shelf
    inner = box(front + layout.wall, layout.floor, front + layout.depth - layout.wall, layout.top)
    assert inner.contains(Polygon(stick))

    q = np.array([info[k] for k in CONFIGS])
    assert scene.robot.within_limits(q).all()
    d_open, d_held = gp.signed_distance(scene, q), gp.signed_distance(held, q)
    assert d_open[0] >= U.MIN_CLEARANCE and d_open[2] >= U.MIN_CLEARANCE  # grasp, home
    assert d_held[1] >= U.MIN_CLEARANCE and d_held[3] >= U.MIN_CLEARANCE  # lift, out
    assert d_open[4] >= U.MIN_CLEARANCE  # pregrasp: outside the box, aligned with the entrance
    pre = U.tcp_pose(scene.robot, info["q_pregrasp"])
    assert pre[0] + U.FINGER_LENGTH / 2 < front and pre[1:] == pytest.approx(info["grasp_tcp"][1:])
    # grasp: gripper horizontal into the box, fingers above and below the stick's near end
    np.testing.assert_allclose(
        U.tcp_pose(scene.robot, info["q_grasp"]), info["grasp_tcp"], atol=1e-9
    )
    upper = Polygon(polygon(scene.robot, info["q_grasp"], "finger_left"))
    lower = Polygon(polygon(scene.robot, info["q_grasp"], "finger_right"))
    near_end = box(stick[0, 0], stick[0, 1], stick[0, 0] + 0.02, stick[2, 1])
    assert upper.bounds[1] > stick[2, 1] and lower.bounds[3] < stick[0, 1]
    assert upper.bounds[0] < near_end.bounds[0] and upper.bounds[2] > near_end.bounds[2]
    assert upper.bounds[0] > front  # the fingers are inside the box
    # closing the gripper makes the stick part of the robot, exactly where it lay
    np.testing.assert_allclose(
        np.sort(polygon(held.robot, info["q_grasp"], "stick"), 0), np.sort(stick, 0), atol=1e-9
    )
    # out: the held stick is clear of the storage's outline (above it)
    out_stick = Polygon(polygon(held.robot, info["q_out"], "stick"))
    assert out_stick.distance(Polygon(storage.exterior).convex_hull) > 0.05


def test_canonical_fetch():
    check_fetch(0)
    scene = gp.make_scene("fetch")
    assert scene.info["layout"] == U.CANONICAL_FETCH
    assert scene.info["stick_length"] == 0.25 and scene.info["stick_width"] == 0.03


@pytest.mark.parametrize("seed", [3, 11])
def test_random_fetch_is_valid_and_seeded(seed):
    check_fetch(seed)
    a, b = gp.make_scene("fetch", seed=seed), gp.make_scene("fetch", seed=seed)
    assert a.info["layout"] == b.info["layout"] != U.CANONICAL_FETCH


def test_random_fetch_benchmark_layouts_differ():
    layouts = [gp.make_scene("fetch", seed=s).info["layout"] for s in range(1, 21)]
    lengths = [lay.stick_length for lay in layouts]
    assert len(set(lengths)) == 20 and min(lengths) >= 0.15 and max(lengths) <= 0.30
    assert np.ptp([lay.front for lay in layouts]) > 0.1
    assert np.ptp([lay.entrance[0] for lay in layouts]) > 0.1


def test_unreachable_layout_is_rejected():
    from dataclasses import replace

    assert U.fetch_configurations(U.CANONICAL_FETCH) is not None
    assert U.fetch_configurations(replace(U.CANONICAL_FETCH, front=1.2)) is None  # out of reach


def test_fetch_errors():
    with pytest.raises(gp.UnknownNameError, match="gripper"):
        gp.make_scene("fetch", gripper="bogus")
    for tries in (0, U.MAX_FETCH_TRIES + 1, True, 2.0):
        with pytest.raises(gp.InputError, match="max_tries"):
            gp.make_scene("fetch", seed=5, max_tries=tries)


def test_fetch_gives_up_after_max_tries(monkeypatch):
    monkeypatch.setattr(U.scene, "fetch_configurations", lambda layout: None)  # no layout is free
    with pytest.raises(gp.InfeasibleProblemError, match="max_tries=2"):
        gp.make_scene("fetch", seed=5, max_tries=2)


def test_bring_out_problem_file_carries_the_fetch_stage_solver_settings():
    from gdnplan import fetch

    config = fetch.bring_out_config()  # read from the problem file: one home
    assert gp.Problem.from_toml(PROBLEMS / "fetch_bring_out.toml").solver == config
    assert config.seed.rrt_step == 0.3 and config.optimizer.interpolated == 3
    with pytest.warns(DeprecationWarning, match="bring_out_config"):
        assert fetch.BRING_OUT_OPTIONS == config
    assert gp.Problem.from_toml(PROBLEMS / "fetch_reach.toml").solver is None


def test_bring_out_problem_file_plans_with_coal():
    """As a user runs it (`gdnplan plan problems/fetch_bring_out.toml --collision coal`): with
    the default RRT-Connect settings this file found no seed path."""
    result = gp.plan(gp.Problem.from_toml(PROBLEMS / "fetch_bring_out.toml"), collision="coal")
    assert result.success and result.min_distance >= 0.0


@pytest.mark.parametrize(
    ("table", "message"),
    [
        ("[solver]\nrrt_stepp = 0.3", "unknown key"),
        ("[solver]\nrrt_step = 'short'", "rrt_step: expected a number"),
        ("[solver]\nccd = 1", "ccd: expected true or false"),
        ("[solver]\nstarts = 2.5", "starts: expected an integer"),
        ("[solver]\nipopt = 1", "ipopt: expected a table"),
        ("solver = 3", "expected a table"),
        ("[seed]\nrrt_stepp = 0.3", "unknown key"),
        ("[seed]\nrrt_step = 'short'", r"\[seed\] rrt_step: expected a number"),
        ("[refine]\nccd = 1", r"\[refine\] ccd: expected true or false"),
        ("[seed]\nstarts = 2.5", "starts: expected an integer"),
        ("[ipopt]\noptions = 1", "options: expected a table"),
        ("[ipopt]\nrrt_step = 0.3", r"belongs in \[seed\]"),
        ("seed = 3", "expected a table"),
    ],
)
def test_bad_solver_table_is_a_problem_file_error(tmp_path, table, message):
    text = (PROBLEMS / "fetch_reach.toml").read_text()
    path = tmp_path / "p.toml"
    path.write_text(text + "\n" + table + "\n" if table.startswith("[") else table + "\n" + text)
    with pytest.raises(gp.ProblemFileError, match=message):
        gp.Problem.from_toml(path)


@pytest.mark.parametrize("name", ["fetch_reach", "fetch_bring_out", "planar2_square", "planar7_d"])
def test_problem_files_are_valid(name):
    cfg = tomllib.loads((PROBLEMS / f"{name}.toml").read_text())
    scene = scene_from_config(cfg)
    q = np.array([cfg["start"]["q"], cfg["goal"]["q"]])
    assert scene.robot.within_limits(q).all()
    assert (gp.signed_distance(scene, q) > cfg["options"]["margin"]).all()
    gp.Problem.from_toml(PROBLEMS / f"{name}.toml")  # raises on provably infeasible problems
    line = q[0] + np.linspace(0, 1, 101)[:, None] * (q[1] - q[0])
    assert gp.signed_distance(scene, line).min() < 0  # the straight path collides: a real task
    if name.startswith("fetch"):
        keys = ("q_home", "q_grasp") if name == "fetch_reach" else ("q_lift", "q_out")
        np.testing.assert_allclose(q, [scene.info[k] for k in keys], atol=1e-6)
        assert scene.robot.info["gripper"] == cfg["robot"]["gripper"] == scene.info["gripper"]


def test_plot(tmp_path):
    scene = gp.make_scene("fetch")
    U.plot_fetch(scene, scene.info["q_grasp"], str(tmp_path / "fetch.png"))
    assert (tmp_path / "fetch.png").stat().st_size > 10_000
