"""Seed paths: RRT-Connect, shortcutting and resampling, every edge certified by coal."""

import numpy as np
import pytest

import gdnplan as gp
import gdnplan.rrt as rrt
from gdnplan.ccd import certify_path
from gdnplan.table2 import reaching_problems

START, GOAL = np.array([1.3, -2.9]), np.array([1.5, 0.1])  # around env a's square


@pytest.fixture(scope="module")
def square():
    return gp.make_scene("a")


@pytest.fixture(scope="module")
def clutter():
    """A (d) problem whose straight line is blocked, and its RRT-Connect path."""
    problem = reaching_problems("d")[0]
    res = rrt.rrt_connect(problem.scene, problem.start, problem.goal, 0.04, seed=0)
    assert res.success and len(res.path) > 3
    return problem, res.path


def test_rrt_connect_path_is_certified_end_to_end(square):
    res = rrt.rrt_connect(square, START, GOAL, clearance=0.02, seed=0)
    assert res.success and res.iterations > 0
    np.testing.assert_array_equal(res.path[0], START)
    np.testing.assert_array_equal(res.path[-1], GOAL)
    assert certify_path(square, res.path, margin=0.02).ok
    assert not certify_path(square, np.stack([START, GOAL]), margin=0.0).ok  # it had to detour


def test_shortcut_keeps_a_certified_subsequence_and_never_rechecks_a_pair(clutter, monkeypatch):
    problem, path = clutter
    checked = []
    edge_free = rrt.edge_free

    def recording(scene, qa, qb, clearance):
        checked.append((qa.tobytes(), qb.tobytes()))
        return edge_free(scene, qa, qb, clearance)

    monkeypatch.setattr(rrt, "edge_free", recording)
    short = rrt.shortcut(problem.scene, path, 0.04, attempts=200, seed=0)
    assert len(checked) == len(set(checked))  # a failed pair is not checked twice
    assert 2 <= len(short) < len(path)
    rows = [int(np.flatnonzero((path == q).all(1))[0]) for q in short]
    assert rows == sorted(rows) and rows[0] == 0 and rows[-1] == len(path) - 1
    assert certify_path(problem.scene, short, margin=0.04).ok
    length = [np.linalg.norm(np.diff(p, axis=0), axis=1).sum() for p in (short, path)]
    assert length[0] < length[1]  # triangle inequality: every shortcut shortens the path


def test_resample_keeps_vertices_and_endpoints(clutter):
    problem, path = clutter
    robot = problem.scene.robot
    dense = rrt.resample(robot, path, 3 * len(path))
    assert dense.shape == (3 * len(path), robot.dof)
    for q in path:  # every vertex survives when n ≥ K
        assert np.any(np.all(np.isclose(dense, q, atol=1e-12), axis=1))
    sparse = rrt.resample(robot, path, 3)
    np.testing.assert_allclose(sparse[[0, -1]], path[[0, -1]], atol=1e-12)


def test_seed_path_has_the_waypoint_count(clutter):
    problem, _ = clutter
    guess, res = rrt.seed_path(problem.scene, problem.start, problem.goal, 20, 0.04, seed=0)
    assert res.success and guess.shape == (20, problem.scene.robot.dof)
    assert certify_path(problem.scene, guess, margin=0.04).ok  # resampling stays on the path


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        ({"step": 0.0}, "rrt_step"),
        ({"step": -1.0}, "rrt_step"),
        ({"step": float("nan")}, "rrt_step"),
        ({"time_limit": -1.0}, "rrt_time"),
        ({"time_limit": float("inf")}, "rrt_time"),
        ({"clearance": float("nan")}, "clearance"),
        ({"max_iterations": 0}, "max_iterations"),
    ],
)
def test_rrt_connect_rejects_settings_that_never_end(square, kwargs, field):
    with pytest.raises(gp.InputError, match=field):
        rrt.rrt_connect(square, START, GOAL, **kwargs)


def test_rrt_connect_stops_at_the_time_limit_inside_the_connect_loop(square, monkeypatch):
    """A tiny step: one greedy connect would take ~10⁶ extensions. On a clock that advances
    10 ms per reading, a 0.5 s limit must stop the search after a few dozen edge checks."""
    now, checks = [0.0], [0]

    def clock() -> float:
        now[0] += 0.01
        return now[0]

    def counted(*args, **kwargs):
        checks[0] += 1
        if checks[0] > 1000:
            raise AssertionError("the connect loop ignores the time limit")
        return edge_free(*args, **kwargs)

    edge_free = rrt.edge_free
    monkeypatch.setattr(rrt.time, "perf_counter", clock)
    monkeypatch.setattr(rrt, "edge_free", counted)
    res = rrt.rrt_connect(square, START, GOAL, step=1e-6, time_limit=0.5, seed=0)
    assert not res.success and 0 < checks[0] <= 100
