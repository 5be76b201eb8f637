"""Time parametrisation: limits at dense samples, the certified path followed, bad input refused."""

import json
from dataclasses import replace
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import assume, example, given, settings
from hypothesis import strategies as st
from scipy.interpolate import CubicSpline, PchipInterpolator
from typer.testing import CliRunner

import gdnplan as gp
from gdnplan.ccd_curve import _total_variation, certify_curve
from gdnplan.cli import app
from gdnplan.distance import signed_distance
from gdnplan.fetch import run_fetch
from gdnplan.limits import MAX_TIMED_SAMPLES
from gdnplan.timing import limit_vector, plan_timing, time_path, urdf_velocity
from gdnplan.trajopt import Problem, plan

ROOT = Path(__file__).resolve().parent.parent
SQUARE = ROOT / "problems" / "planar2_square.toml"
REL = 1e-6  # relative slack of the limit checks (rounding)


@pytest.fixture(scope="module")
def free():
    """planar2 and planar7 (by dof) with no obstacles: every curve is free (distance +inf)."""
    empty = gp.make_scene("a").with_obstacles([])
    return {n: empty.with_robot(gp.load_robot(f"planar{n}")) for n in (2, 7)}


@pytest.fixture(scope="module")
def square_plan():
    return plan(Problem.from_toml(SQUARE), collision="coal")


@st.composite
def paths(draw, dofs=(1, 2, 3, 4, 5, 6, 7)):
    """(T, dof) waypoint paths with steps of mixed sizes, some repeated waypoints, and limits."""
    dof = draw(st.sampled_from(dofs))
    n = draw(st.integers(2, 10))
    seed = draw(st.integers(0, 2**31))
    rng = np.random.default_rng(seed)
    steps = rng.normal(0.0, draw(st.sampled_from([0.01, 0.1, 0.5])), (n - 1, dof))
    steps[rng.random(n - 1) < 0.15] = 0.0  # repeated waypoints
    q = np.clip(np.cumsum(np.vstack([rng.uniform(-1, 1, dof), steps]), axis=0), -3.0, 3.0)
    v = rng.uniform(0.2, 4.0, dof)
    a = rng.uniform(0.5, 20.0, dof)
    return q, v, a


def finite_differences(t, q):
    qd = np.diff(q, axis=0) / np.diff(t)[:, None]
    mid = (t[1:] + t[:-1]) / 2
    qdd = np.diff(qd, axis=0) / np.diff(mid)[:, None]
    return qd, qdd


def distance_to_polygon(points, q):
    """(N,) joint-space distance of each point to the polygon through the waypoints q."""
    a, b = q[:-1][None], q[1:][None]
    ab = b - a
    den = np.maximum(np.sum(ab * ab, axis=2), 1e-300)
    s = np.clip(np.sum((points[:, None] - a) * ab, axis=2) / den, 0.0, 1.0)
    return np.min(np.linalg.norm(points[:, None] - (a + s[..., None] * ab), axis=2), axis=1)


def check_common(traj, q):
    times = traj.times
    assert times.shape == (len(q),) and times[0] == 0.0 and np.all(np.diff(times) >= 0)
    moved = np.any(np.diff(q, axis=0) != 0, axis=1)
    assert np.all(np.diff(times)[moved] > 0)  # only a repeated waypoint takes no time
    np.testing.assert_allclose(traj.evaluate(times)[0], q, atol=1e-9)  # q_k at t_k
    t, qs = traj.sample(traj.duration / 300 if traj.duration > 0 else 0.01)
    assert t[0] == 0.0 and t[-1] == traj.duration and np.all(np.diff(t) > 0)
    np.testing.assert_allclose(qs[0], q[0], atol=1e-12)
    np.testing.assert_allclose(qs[-1], q[-1], atol=1e-9)
    return t, qs


@settings(max_examples=60, deadline=None)
@given(paths())
def test_linear_follows_the_polygon_within_the_velocity_limits(case):
    q, v, _ = case
    traj = time_path(q, v)
    assert traj.kind == "linear" and traj.max_acceleration is None
    t, qs = check_common(traj, q)
    assert np.max(distance_to_polygon(qs, q)) < 1e-9
    qd, _ = finite_differences(t, qs)
    assert np.all(np.abs(qd) <= v * (1 + REL))
    # time-optimal along the polygon: some joint is at its limit on every moving segment
    tau = np.diff(traj.times)
    moving = tau > 0
    assert np.allclose(np.max(np.abs(np.diff(q, axis=0)) / v, axis=1)[moving], tau[moving])


@settings(max_examples=60, deadline=None)
@given(paths())
def test_stop_follows_the_polygon_within_velocity_and_acceleration_limits(case):
    q, v, a = case
    traj = time_path(q, v, a)  # no scene: the exact polygon, at rest at every waypoint
    assert traj.kind == "stop"
    t, qs = check_common(traj, q)
    assert np.max(distance_to_polygon(qs, q)) < 1e-9
    qd, qdd = finite_differences(t, qs)
    assert np.all(np.abs(qd) <= v * (1 + REL))
    assert np.all(np.abs(qdd) <= a * (1 + 1e-3))
    _, qd_at, _ = traj.evaluate(traj.times)
    np.testing.assert_allclose(qd_at, 0.0, atol=1e-9)  # at rest at the corners
    _, qd_all, qdd_all = traj.evaluate(np.linspace(0, traj.duration, 2000))
    assert np.all(np.abs(qd_all) <= v * (1 + REL)) and np.all(np.abs(qdd_all) <= a * (1 + REL))


SHORT_TURN = (  # toppra calls it uncontrollable with grid points 1e-6 before the knots
    np.array([[-0.14495116, -0.27884981], [-0.15369294, -0.29929403], [-0.13688595, -0.29792866]]),
    np.array([3.38985287, 2.42585655]),
    np.array([7.70610049, 1.45238235]),
)


@settings(max_examples=40, deadline=None)
@given(paths(dofs=(2, 7)))
@example(SHORT_TURN)
def test_smooth_respects_the_limits_and_stays_in_the_waypoint_boxes(free, case):
    q, v, a = case
    traj = time_path(q, v, a, free[q.shape[1]])
    if np.all(q == q[0]):  # no path to smooth: at rest
        assert traj.kind == "stop" and traj.duration == 0
        return
    assert traj.kind == "smooth" and traj.min_distance == np.inf
    t, qs = check_common(traj, q)
    tt = np.linspace(0.0, traj.duration, 4000)
    q_all, qd_all, qdd_all = traj.evaluate(tt)
    assert np.all(np.abs(qd_all) <= v * (1 + REL))
    assert np.all(np.abs(qdd_all) <= a * (1 + REL))
    qd, qdd = finite_differences(t, qs)
    assert np.all(np.abs(qd) <= v * (1 + REL)) and np.all(np.abs(qdd) <= a * (1 + 1e-2))
    np.testing.assert_allclose(traj.evaluate([0.0, traj.duration])[1], 0.0, atol=1e-6)
    # PCHIP is shape preserving: between waypoints k and k+1 every joint stays between them
    k = np.clip(np.searchsorted(traj.times, tt, side="right") - 1, 0, len(q) - 2)
    lo, hi = np.minimum(q[k], q[k + 1]), np.maximum(q[k], q[k + 1])
    assert np.all((q_all >= lo - 1e-9) & (q_all <= hi + 1e-9))


@settings(max_examples=15, deadline=None)
@given(paths(dofs=(2, 7)), st.floats(-2.5, 3.0))
@example(SHORT_TURN, -2.5)
def test_the_smooth_timing_does_not_depend_on_the_units_of_time(free, case, exponent):
    """Limits v k and a k² give the same motion k times faster (a time-optimal timing scales
    exactly so). toppra's tolerances are absolute: under small limits (a ~ 1e-6 rad/s²) its
    path speed broke the acceleration limit between grid points so far that the stretch was
    25 (1.02 at a ~ 1), and the smooth timing took 7 times longer than stopping at every
    waypoint (timing_toppra.time_scale normalises the limits first)."""
    q, v, a = case
    assume(not np.all(q == q[0]))
    k = 10.0**exponent
    base, scaled = (
        time_path(q, v, a, free[q.shape[1]]),
        time_path(q, v * k, a * k**2, free[q.shape[1]]),
    )
    assert base.kind == scaled.kind == "smooth"
    assert scaled.duration * k == pytest.approx(base.duration, rel=0.02)
    _, qd, qdd = scaled.evaluate(np.linspace(0.0, scaled.duration, 4000))
    assert np.all(np.abs(qd) <= v * k * (1 + REL)) and np.all(np.abs(qdd) <= a * k**2 * (1 + REL))


@settings(max_examples=30, deadline=None)
@given(st.integers(1, 323), st.integers(0, 2), st.integers(0, 1))
@example(200, 0, 0)  # chord underflowed to 0: two distinct waypoints on one knot (ValueError)
@example(157, 0, 1)  # the cubic's coefficients overflowed: NaN configurations (InputError)
def test_a_tiny_waypoint_step_is_timed_through_every_waypoint(free, exponent, where, joint):
    """A step of 10^−exponent rad anywhere in the path: the smooth curve where float64 holds
    it, else the stop polygon (timing_toppra.pchip_curve), never an error; each waypoint is
    reached at its time and the limits hold."""
    step = np.zeros(2)
    step[joint] = 10.0**-exponent
    corner = [np.zeros(2), np.array([1.0, 1.0]), np.array([2.0, 0.0])]
    q = np.array([*corner[: where + 1], corner[where] + step, *corner[where + 1 :]])
    traj = time_path(q, 1.0, 2.0, free[2])
    assert traj.kind in ("smooth", "stop")
    np.testing.assert_allclose(traj.evaluate(traj.times)[0], q, rtol=0, atol=1e-9)
    _, qd, qdd = traj.evaluate(np.linspace(0.0, traj.duration, 2000))
    assert np.all(np.abs(qd) <= 1.0 + REL) and np.all(np.abs(qdd) <= 2.0 + REL)


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**31), st.integers(1, 4), st.integers(2, 8))
def test_total_variation_of_a_cubic_is_exact(seed, dof, n):
    rng = np.random.default_rng(seed)
    x = np.cumsum(rng.uniform(0.1, 1.0, n))
    curve = CubicSpline(x, rng.normal(size=(n, dof)), axis=0)  # overshoots: interior extrema
    cut = np.sort(rng.uniform(0, 1, 3))
    sa = x[:-1] + cut[0] * np.diff(x)
    sb = x[:-1] + cut[2] * np.diff(x)
    tv = _total_variation(curve, sa, sb)
    for i in range(n - 1):
        dense = curve(np.linspace(sa[i], sb[i], 20001))
        sampled = np.sum(np.abs(np.diff(dense, axis=0)), axis=0)
        assert np.all(tv[i] >= sampled - 1e-12)  # never below (the certificate's side)
        np.testing.assert_allclose(tv[i], sampled, rtol=1e-6, atol=1e-9)


def test_curve_certificate_is_sound_and_rejects_a_curve_through_the_square():
    scene = gp.make_scene("a")
    free = plan(Problem.from_toml(SQUARE), collision="coal")
    knots = np.linspace(0, 1, len(free.q))
    cert = certify_curve(scene, PchipInterpolator(knots, free.q, axis=0))
    assert cert.ok and cert.lower_bound > 0
    dense = PchipInterpolator(knots, free.q, axis=0)(np.linspace(0, 1, 3001))
    assert np.min(signed_distance(scene, dense)) >= cert.lower_bound - 1e-9
    line = np.linspace([1.3, -2.9], [1.5, 0.1], 6)  # straight through env a's square
    bad = certify_curve(scene, PchipInterpolator(np.arange(6.0), line, axis=0))
    assert not bad.ok and bad.lower_bound == -np.inf


def test_plan_times_the_certified_path(square_plan):
    r = square_plan
    assert r.success and r.trajectory.kind == "linear"
    assert r.times.shape == (len(r.q),) and r.times[0] == 0 and np.all(np.diff(r.times) > 0)
    assert r.duration == r.times[-1] > 0
    t, q = r.sample(0.01)
    np.testing.assert_allclose(q[[0, -1]], r.q[[0, -1]], atol=1e-12)
    v = gp.load_robot("planar2").model.velocityLimit
    assert np.all(np.abs(np.diff(q, axis=0)) / np.diff(t)[:, None] <= v * (1 + REL))


def test_plan_with_acceleration_limits_certifies_its_smooth_curve():
    r = plan(Problem.from_toml(SQUARE), collision="coal", max_acceleration=4.0)
    assert r.success and r.trajectory.kind == "smooth"
    assert r.trajectory.min_distance > 0  # the curve's own proof
    t, q = r.sample(0.005)
    assert np.min(signed_distance(gp.make_scene("a"), q)) >= r.trajectory.min_distance - 1e-9
    qd, qdd = finite_differences(t, q)
    assert np.all(np.abs(qd) <= 2.0 * (1 + REL)) and np.all(np.abs(qdd) <= 4.0 * (1 + 1e-2))


def test_failed_plan_has_no_trajectory(square_plan):
    scene = gp.make_scene("a")
    assert plan_timing(scene, square_plan.q, False) == (None, "")
    failed = replace(square_plan, success=False, trajectory=None)
    assert failed.times is None and failed.duration is None
    with pytest.raises(gp.InputError, match="no trajectory"):
        failed.sample(0.01)


def test_a_urdf_without_velocity_limits_gives_no_timing_and_says_which_joint():
    scene = gp.make_scene("a")
    model = pin.Model(scene.robot.model)
    model.velocityLimit = np.array([2.0, 0.0])  # URDF velocity="0"
    robot = replace(scene.robot, model=model)
    with pytest.raises(gp.InputError, match="joint2"):
        urdf_velocity(robot)
    traj, note = plan_timing(scene.with_robot(robot), np.zeros((2, 2)), True)
    assert traj is None and "joint2" in note and "max_velocity" in note
    traj, note = plan_timing(scene.with_robot(robot), np.zeros((2, 2)), True, max_velocity=1.0)
    assert traj is not None and note == ""


@pytest.mark.parametrize("dt", [0.0, -0.1, float("nan"), float("inf"), True, "0.1", None])
def test_bad_dt_is_bad_input(square_plan, dt):
    with pytest.raises(gp.InputError, match="dt"):
        square_plan.sample(dt)


def test_too_many_samples_is_bad_input(square_plan):
    with pytest.raises(gp.InputError, match=str(MAX_TIMED_SAMPLES)):
        square_plan.sample(square_plan.duration / (2 * MAX_TIMED_SAMPLES))


@pytest.mark.parametrize(
    "limit", [0.0, -1.0, float("nan"), float("inf"), True, [1.0], [1.0, -2.0], "2", [[1, 2]]]
)
def test_bad_limits_are_bad_input(limit):
    with pytest.raises(gp.InputError, match="max_velocity"):
        limit_vector(limit, 2, "max_velocity", "rad/s")
    with pytest.raises(gp.InputError, match="max_acceleration"):
        time_path(np.zeros((3, 2)), 1.0, limit)


def test_plan_refuses_bad_limits_before_solving():
    problem = Problem.from_toml(SQUARE)
    with pytest.raises(gp.InputError, match="max_acceleration"):
        plan(problem, collision="coal", max_acceleration=-1.0)
    with pytest.raises(gp.InputError, match="max_velocity"):
        plan(problem, collision="coal", max_velocity=[1.0, 2.0, 3.0])


@pytest.mark.parametrize("q", [np.zeros((0, 2)), np.zeros(3), np.array([[0.0, np.nan]])])
def test_bad_waypoints_are_bad_input(q):
    with pytest.raises(gp.InputError, match="q"):
        time_path(q, 1.0)


def test_bad_evaluation_times_are_bad_input(square_plan):
    with pytest.raises(gp.InputError, match="t"):
        square_plan.trajectory.evaluate([0.0, np.nan])


def test_cli_json_carries_joint_names_and_times():
    result = CliRunner().invoke(
        app, ["plan", str(SQUARE), "--collision", "coal", "--json", "--max-acceleration", "4"]
    )
    assert result.exit_code == 0, result.output
    out = json.loads(result.stdout)  # stage lines go to stderr
    assert out["joint_names"] == ["joint1", "joint2"] and out["timing"] == "smooth"
    t = np.array(out["t"])
    assert len(t) == len(out["q"]) and t[0] == 0 and np.all(np.diff(t) > 0)
    assert out["duration"] == t[-1]


def test_cli_refuses_a_bad_acceleration_limit():
    result = CliRunner().invoke(
        app, ["plan", str(SQUARE), "--collision", "coal", "--max-acceleration", "0"]
    )
    assert isinstance(result.exception, gp.InputError)  # main() turns it into exit status 2
    assert "max_acceleration" in str(result.exception)


def test_scripted_fetch_stages_carry_times():
    grasp, lift = run_fetch(0, collision="coal", stages=("grasp", "lift"))
    assert grasp.times.tolist() == [0.0, 0.0]
    summary = lift.summary()
    assert summary["joint_names"] == ["shoulder_lift_joint", "elbow_joint", "wrist_1_joint"]
    t = np.array(summary["t"])
    assert len(t) == len(summary["q"]) and t[0] == 0 and np.all(np.diff(t) > 0)


def test_smooth_timing_without_toppra_says_how_to_install_it(free, monkeypatch):
    import sys

    monkeypatch.setitem(sys.modules, "toppra", None)  # import toppra raises ImportError
    with pytest.raises(gp.InputError, match="pip install toppra"):
        time_path(np.array([[0.0, 0.0], [0.5, 0.2]]), 1.0, 2.0, free[2])


@settings(max_examples=30, deadline=None)
@given(st.integers(0, 2**31), st.integers(1, 4), st.integers(2, 6))
def test_cell_bounds_hold_and_the_acceleration_bound_is_exact(seed, dof, n):
    """The per-cell bounds are ≥ the motion's |q̇|, |q̈| everywhere in the cell; |q̈|'s is its max."""
    from scipy.interpolate import PchipInterpolator

    from gdnplan.timing import cell_bounds

    rng = np.random.default_rng(seed)
    knots = np.concatenate([[0.0], np.cumsum(rng.uniform(0.1, 1.0, n - 1))])
    curve = PchipInterpolator(knots, rng.uniform(-1, 1, (n, dof)), axis=0)
    grid = np.unique(np.concatenate([knots, rng.uniform(0, knots[-1], 3 * n)]))
    sd = rng.uniform(0.0, 2.0, len(grid))
    u = (sd[1:] ** 2 - sd[:-1] ** 2) / (2 * np.diff(grid))
    vel, acc = cell_bounds(curve, grid, sd, u)
    for i in range(len(grid) - 1):
        end = grid[i + 1] - 1e-12 * (grid[i + 1] - grid[i])  # the left limit: its own cubic
        s = np.linspace(grid[i], end, 2001)
        w = sd[i] ** 2 + 2 * u[i] * (s - grid[i])
        qd = curve(s, 1) * np.sqrt(np.maximum(w, 0))[:, None]
        qdd = curve(s, 2) * w[:, None] + curve(s, 1) * u[i]
        assert np.all(np.abs(qd).max(0) <= vel[i] * (1 + 1e-9) + 1e-12)
        assert np.all(np.abs(qdd).max(0) <= acc[i] * (1 + 1e-9) + 1e-12)
        np.testing.assert_allclose(np.abs(qdd).max(0), acc[i], rtol=1e-3, atol=1e-9)


# a path of planar2 in scene (a) certified with clearance ≥ 0.19 m whose PCHIP curve passes
# 0.053 m from the square: the smooth timing must keep the plan's clearance, not only d > 0
BULGING = np.array([[-2.065, -0.034], [-0.894, 2.086], [-0.193, 0.344]])


@settings(max_examples=12, deadline=None)
@given(st.integers(0, 2**31), st.sampled_from([0.0, 0.5, 0.9]))
@example(-1, 0.75)  # BULGING at clearance 0.15 m
def test_the_executed_trajectory_keeps_the_plans_clearance(seed, share):
    scene = gp.make_scene("a")
    rng = np.random.default_rng(max(seed, 0))
    q = BULGING if seed < 0 else rng.uniform(-3.0, 3.0, (3, 2))
    cert = gp.certify_path(scene, q, margin=0.0)
    if not cert.ok:
        return
    clearance = share * cert.lower_bound  # the polygon is certified with this clearance
    traj = time_path(q, 1.0, 4.0, scene, clearance=clearance)
    if traj.kind == "smooth":
        assert traj.min_distance > clearance
    _, qs = traj.sample(traj.duration / 2000)
    assert np.min(signed_distance(scene, qs)) > clearance


def test_plan_times_a_smooth_curve_only_at_its_clearance(square_plan):
    scene = gp.make_scene("a")
    traj, _ = plan_timing(scene, BULGING, True, 1.0, 4.0, clearance=0.15)
    assert traj.kind == "stop"  # the curve dips to 0.053 m: the certified polygon instead
    with pytest.raises(gp.InputError, match="clearance"):
        time_path(BULGING, 1.0, 4.0, scene, clearance=-0.1)
