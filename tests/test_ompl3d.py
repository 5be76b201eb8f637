"""OMPL's planners on a 3-D scene through the exact protocol: the same certified validity."""

import numpy as np
import pytest

from gdnplan.arm3d import Scene3D, box_obstacle, certify_path3d, load_robot3d

pytest.importorskip("ompl")

from gdnplan.ompl_planner import plan_ompl

START = np.array([-0.6, -1.2, 1.2, -1.5, -1.57, 0.0])
GOAL = np.array([0.6, -1.2, 1.2, -1.5, -1.57, 0.0])


def test_an_ompl_path_in_3d_is_certified():
    scene = Scene3D(load_robot3d("ur5e"), [box_obstacle((0.1, 0.1, 0.6), (0.45, 0.0, 0.3))])
    lower, upper = np.full(6, -np.pi), np.full(6, np.pi)
    result = plan_ompl(scene, START, GOAL, 0.02, time_limit=5.0, lower=lower, upper=upper)
    assert result.success, result.status
    np.testing.assert_array_equal(result.path[0], START)
    np.testing.assert_array_equal(result.path[-1], GOAL)
    assert result.clearance > 0.02
    assert certify_path3d(scene, result.path, 0.02).ok  # independently of plan_ompl's own


def test_ompl_states_hold_contact_only_pairs_at_zero():
    """OMPL's state checker is the certificate's: a UR5e configuration with the wrist inside
    the forearm (a contact-only pair, true d < 0) is invalid at any clearance, one clear of
    everything at a clearance below its distance is valid."""
    from ompl import base as ob

    from gdnplan.arm3d import signed_distance3d
    from gdnplan.ompl_planner import _setup

    robot = load_robot3d("ur5e")
    scene = Scene3D(robot, [])
    inside = np.array([0.0, -1.6902, 0.5121, 1.4892, -2.4591, -3.2126])
    assert signed_distance3d(scene, inside)[0] < -0.005
    si, _, _ = _setup(ob, scene, robot.lower, robot.upper, 0.0)
    for q, valid in ((inside, False), (START, True)):
        state = si.allocState()
        for j, value in enumerate(q):
            state[j] = float(value)
        assert si.isValid(state) is valid


def test_ompl_honours_its_time_limit_in_3d(monkeypatch):
    """OMPL's path simplifier ran every step once whatever the time left, each with many
    certified motion checks: a 0.05 s plan took 0.8 s, a 3 s one 6.4 s. Past the time limit
    motions are refused unchecked; the path (certified motion by motion) is kept as it was."""
    import time

    import gdnplan.ompl_planner as op

    scene = Scene3D(load_robot3d("ur5e"), [box_obstacle((0.1, 0.1, 0.6), (0.45, 0.0, 0.3))])
    real_edge_free, real_certify, called = op.edge_free, op.certify, []

    def slow_edge_free(*args):
        time.sleep(0.03)  # a costly certificate, whatever the machine's load
        return real_edge_free(*args)

    def timed_certify(*args, **kwargs):
        called.append(time.perf_counter())
        return real_certify(*args, **kwargs)

    monkeypatch.setattr(op, "edge_free", slow_edge_free)
    monkeypatch.setattr(op, "certify", timed_certify)
    lower, upper = np.full(6, -np.pi), np.full(6, np.pi)
    t0 = time.perf_counter()
    result = plan_ompl(scene, START, GOAL, 0.02, time_limit=0.5, lower=lower, upper=upper)
    if not called:  # no path within the limit: it returned at once
        assert not result.success and time.perf_counter() - t0 < 0.5 + 0.5
        return
    assert called[0] - t0 < 0.5 + 0.5  # one motion check under way at most
    assert not result.success or certify_path3d(scene, result.path, 0.02).ok


@pytest.mark.parametrize("seed", [-1, 2**32, 1.5, "a", True, None])
def test_a_seed_that_is_no_ompl_seed_is_refused(seed):
    """OMPL's binding raised TypeError for −1, int() a ValueError for "a", and 1.5 became 1."""
    from gdnplan.errors import InputError

    scene = Scene3D(load_robot3d("ur5e"), [box_obstacle((0.1, 0.1, 0.6), (0.45, 0.0, 0.3))])
    with pytest.raises(InputError, match=r"^seed: expected an integer in \[0, 4294967295\]"):
        plan_ompl(scene, START, GOAL, 0.02, time_limit=0.1, seed=seed)
