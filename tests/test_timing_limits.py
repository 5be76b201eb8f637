"""time_path at extreme limits and bad paths: an InputError naming the culprit, or a finite
timed trajectory whose samples are finite and stay on the waypoint polygon's box."""

import math

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

import gdnplan as gp
from gdnplan.limits import MAX_TIMED_SAMPLES
from gdnplan.timing import LIMIT_RANGE, MAX_ANGLE, time_path

EXTREME = st.one_of(
    st.sampled_from([1e-310, 5e-324, 1e-300, 1e-12, 1e-7, 1e-6, 1.0, 1e9, 2e9, 1e300, 1.7e308]),
    st.floats(min_value=5e-324, max_value=1.7e308, allow_nan=False, allow_infinity=False),
)


@pytest.fixture(scope="module")
def free2():
    return gp.make_scene("a").with_obstacles([])


def _path(seed: int, scale: float) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return np.cumsum(rng.normal(0.0, scale, (4, 2)), axis=0)


def _check(traj, q: np.ndarray) -> None:
    assert math.isfinite(traj.duration) and traj.duration >= 0
    assert np.all(np.isfinite(traj.times))
    dt = max(traj.duration / 50, 1e-300) if traj.duration > 0 else 0.01
    try:
        t, qs = traj.sample(dt)
    except gp.InputError as e:  # a too-fine dt is refused, never an overflow
        assert str(MAX_TIMED_SAMPLES) in str(e)
        t = np.linspace(0.0, traj.duration, 51)
        qs = traj.evaluate(t)[0]
    assert np.all(np.isfinite(t)) and np.all(np.isfinite(qs))
    pad = 1e-9 * (1 + np.abs(q).max())
    assert np.all(qs >= q.min(0) - pad) and np.all(qs <= q.max(0) + pad)


@settings(max_examples=60, deadline=None)
@given(
    v=EXTREME,
    a=st.one_of(st.none(), EXTREME),
    seed=st.integers(0, 2**31),
    scale=st.sampled_from([1e-300, 1e-9, 0.3, 1e3, 1e5]),
)
@example(v=1e-310, a=None, seed=0, scale=0.3)  # the audit's case: an infinite duration
@example(v=1e-6, a=1e-6, seed=1, scale=1e5)  # the slowest accepted limits, long steps
@example(v=1e9, a=1e9, seed=2, scale=1e-300)  # the fastest, denormal-scale steps
@example(v=1e9, a=None, seed=0, scale=1e-300)  # linear timing: denormal segment times
@example(v=1e-6, a=1e9, seed=0, scale=1e-300)  # stop timing: σ̈ = a/|Δq| overflows
def test_extreme_limits_are_refused_or_give_a_finite_trajectory(v, a, seed, scale):
    q = _path(seed, scale)
    low, high = LIMIT_RANGE
    try:
        traj = time_path(q, v, a)
    except gp.InputError as e:
        bad_v = not low <= v <= high
        assert ("max_velocity" if bad_v else "max_acceleration") in str(e) or "q:" in str(e)
        assert bad_v or a is None or not low <= a <= high or np.abs(q).max() > MAX_ANGLE
        return
    assert low <= v <= high and (a is None or low <= a <= high)
    _check(traj, q)


@settings(max_examples=15, deadline=None)
@given(v=st.sampled_from([1e-6, 1e-3, 1.0, 1e9]), a=st.sampled_from([1e-6, 1.0, 1e9]))
def test_smooth_at_extreme_limits_is_finite(free2, v, a):
    q = np.array([[0.0, 0.0], [0.4, 0.2], [0.5, -0.3]])
    _check(time_path(q, v, a, free2), q)


@pytest.mark.parametrize(
    "q",
    [
        np.zeros((3, 0)),
        np.zeros((0, 2)),
        "abc",
        [[1, "x"]],
        np.array([[1 + 2j, 0]]),
        np.array([[0.0, 1e300]]),
        [[0.0], [0.0, 1.0]],
    ],
)
def test_bad_path_shapes_and_values_are_input_errors(q):
    with pytest.raises(gp.InputError, match="q"):
        time_path(q, 1.0)


def test_sample_of_a_long_trajectory_with_a_tiny_dt_is_refused():
    traj = time_path(np.array([[0.0], [1e6]]), 1e-6)
    with pytest.raises(gp.InputError, match="dt"):
        traj.sample(1e-300)


def test_a_scene_whose_robot_does_not_match_the_path_is_refused(free2):
    q = np.zeros((3, 3))
    q[1:, 0] = [0.2, 0.4]
    with pytest.raises(gp.InputError, match=r"^scene: its robot has 2 joints, q has 3 columns"):
        time_path(q, 1.0, 1.0, free2)
    with pytest.raises(gp.InputError, match=r"^scene: expected a Scene"):
        time_path(q, 1.0, 1.0, "a")
