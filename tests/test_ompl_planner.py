"""gdnplan.ompl_planner: OMPL's planners on the certified validity rule (smoke tests, fast)."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

from gdnplan.ccd import certify_path
from gdnplan.distance import signed_distance
from gdnplan.errors import InputError
from gdnplan.trajopt import Problem, straight_line

pytest.importorskip("ompl")

from gdnplan.ompl_planner import PLANNERS, plan_ompl


@pytest.fixture(scope="module")
def square() -> Problem:
    """planar2 around the square: the straight joint-space line is not free."""
    return Problem.from_toml("planar2_square")


@pytest.mark.parametrize("planner", ["rrtconnect", "aorrtc"])
def test_paths_are_certified_around_the_square(square, planner):
    """The path joins start and goal, stays in the limits, and is certified above the
    clearance; coal on a dense sampling of it (independent of the certificate) agrees."""
    p, c = square, square.certified_clearance
    assert not certify_path(p.scene, straight_line(p.start, p.goal, 20), margin=c).ok
    r = plan_ompl(p.scene, p.start, p.goal, c, planner, time_limit=1.0, seed=0)
    assert r.success, r.status
    assert r.planner == planner
    np.testing.assert_array_equal(r.path[0], p.start)
    np.testing.assert_array_equal(r.path[-1], p.goal)
    assert len(r.path) >= 3  # it had to bend
    assert np.all(r.path >= p.lower) and np.all(r.path <= p.upper)
    assert r.certificate.ok and r.clearance > c
    s = np.linspace(0.0, 1.0, 200)[:, None]
    dense = np.vstack([a + s * (b - a) for a, b in zip(r.path[:-1], r.path[1:], strict=True)])
    assert signed_distance(p.scene, dense).min() > c


def test_an_impossible_clearance_fails_cleanly(square):
    """Start and goal are not valid at 10 m clearance: no path, success False, no crash."""
    p = square
    r = plan_ompl(p.scene, p.start, p.goal, 10.0, "rrtconnect", time_limit=0.05)
    assert not r.success
    assert r.path.shape == (0, 2) and r.clearance == -np.inf


def test_bad_input_and_missing_ompl(square, monkeypatch):
    p = square
    with pytest.raises(InputError, match="planner"):
        plan_ompl(p.scene, p.start, p.goal, 0.02, "prm")
    with pytest.raises(InputError, match="time_limit"):
        plan_ompl(p.scene, p.start, p.goal, 0.02, "rrtconnect", time_limit=0.0)
    assert set(PLANNERS) >= {"rrtconnect", "bitstar", "aorrtc"}
    monkeypatch.setitem(sys.modules, "ompl", None)  # import ompl now raises ImportError
    with pytest.raises(InputError, match=r"gdnplan\[bench\]"):
        plan_ompl(p.scene, p.start, p.goal, 0.02)


NAN = float("nan")


@pytest.mark.parametrize(
    ("lower", "upper", "match"),
    [
        ([0.0], None, r"lower: expected shape \(2,\)"),  # was IndexError
        ([1.0, 1.0], [0.0, 0.0], r"lower\[0\] = 1 rad must be below upper\[0\]"),  # was OMPL's
        ([NAN, 0.0], None, "lower: contains NaN"),  # was 'q_path: contains NaN'
        (None, [1.0, float("inf")], "upper: contains NaN or infinite"),
        (None, [10.0, 1.0], r"upper\[0\] = 10 rad is outside the robot's joint range"),
        ([True, False], None, "lower: expected real numbers"),
        ("ab", None, r"lower: expected shape \(2,\)"),
        ([[0.0], [0.0, 1.0]], None, "lower: expected shape"),
        ([-1.0, -1.0], [0.0, 0.0], r"start\[0\] = .* is outside the joint box"),
    ],
)
def test_bad_joint_boxes_are_input_errors_naming_them(square, lower, upper, match):
    p = square
    with pytest.raises(InputError, match=match):
        plan_ompl(p.scene, p.start, p.goal, 0.02, lower=lower, upper=upper)


def test_a_box_within_the_robots_limits_is_accepted(square):
    p = square
    r = plan_ompl(
        p.scene, p.start, p.goal, 0.02, time_limit=0.5, lower=p.lower * 0.99, upper=p.upper
    )
    assert r.path.shape[1] == 2
    assert np.all(r.path >= p.lower * 0.99 - 1e-12)


BAD_COMPARE_FLAGS = [
    (["--envs", "zz"], "--envs: unknown 'zz'"),  # KeyError
    (["--problems", "0"], "--problems"),  # an empty table
    (["--first", "-5"], "--first"),
    (["--budgets", "nan"], "--budgets"),  # InputError traceback after gdnplan's solves
    (["--budgets", "1e9"], "--budgets"),
    (["--planners", "nosuch"], "--planners: unknown 'nosuch'"),
    (["--threads", "0"], "--threads"),  # torch's RuntimeError
    (["--seeds", "0"], "--seeds/--kinds"),
    (["--kinds", "nosuch"], "--seeds/--kinds"),
    (["--seed", "-1"], "--seed"),
    (["--render", "/no/such.jsonl"], "--render"),
    (["--out", "table.txt"], "--out"),
]


@pytest.mark.parametrize(("flags", "message"), BAD_COMPARE_FLAGS, ids=lambda x: str(x)[:30])
def test_ompl_compare_refuses_bad_flags_before_any_work(flags, message, capsys, monkeypatch):
    """benchmarks/ompl_compare.py checks every flag up front: exit status 2 and one line naming
    the flag, before a problem is drawn or a results file truncated."""
    import importlib.util

    path = Path(__file__).resolve().parent.parent / "benchmarks" / "ompl_compare.py"
    spec = importlib.util.spec_from_file_location("ompl_compare", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    monkeypatch.setattr(module, "reaching_problems", lambda *a, **k: pytest.fail("work began"))
    with pytest.raises(SystemExit) as e:
        module.main(["--out", "/tmp/never_written.md", *flags])
    assert e.value.code == 2
    assert message in capsys.readouterr().err
