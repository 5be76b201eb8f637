"""Timed 3-D trajectories: URDF velocity limits, toppra limits at dense samples, the smooth
curve's 3-D certificate (sound against dense coal samples, a curve through a box refused)."""

import xml.etree.ElementTree as ET

import numpy as np
import pytest
from scipy.interpolate import PchipInterpolator

from gdnplan.arm3d import Scene3D, box_obstacle, certify_path3d, load_robot3d
from gdnplan.arm3d.distance3d import signed_distance3d
from gdnplan.ccd_curve import certify_curve
from gdnplan.timing import plan_timing, time_path

REL = 1e-6  # relative slack of the velocity checks (rounding)
START = [-0.6, -1.2, 1.2, -1.5, -1.57, 0.0]
UP = [0.0, -1.57, 0.0, -1.57, -1.57, 0.0]  # the arm raised over the post
GOAL = [0.6, -1.2, 1.2, -1.5, -1.57, 0.0]


@pytest.fixture(scope="module")
def post():
    """The UR5e beside a post; START → UP → GOAL goes over it (certified in the test)."""
    return Scene3D(load_robot3d("ur5e"), [box_obstacle((0.1, 0.1, 0.6), (0.45, 0.0, 0.3))])


def urdf_velocities(robot) -> dict[str, float]:
    """Velocity limits (rad/s) of the URDF's joints, read from its XML (not from Pinocchio)."""
    root = ET.parse(robot.info["urdf"]).getroot()
    return {
        j.get("name"): float(j.find("limit").get("velocity"))
        for j in root.iter("joint")
        if j.find("limit") is not None and j.find("limit").get("velocity") is not None
    }


@pytest.mark.parametrize("name", ["ur5e", "panda"])
def test_3d_timing_uses_the_urdf_velocity_limits(name):
    robot = load_robot3d(name)
    scene = Scene3D(robot, [])
    q = np.array([np.zeros(robot.dof), np.full(robot.dof, 0.3)])
    q = np.clip(q, robot.lower, robot.upper)
    traj, note = plan_timing(scene, q, True)
    assert note == "" and traj.kind == "linear"
    xml = urdf_velocities(robot)
    expected = np.array([xml[j] for j in robot.joint_names])
    np.testing.assert_allclose(traj.max_velocity, expected)
    step = np.abs(q[1] - q[0])
    assert traj.duration == pytest.approx(np.max(step / expected))


def finite_differences(t, q):
    qd = np.diff(q, axis=0) / np.diff(t)[:, None]
    mid = (t[1:] + t[:-1]) / 2
    return qd, np.diff(qd, axis=0) / np.diff(mid)[:, None]


def test_smooth_3d_timing_keeps_the_limits_and_its_certificate(post):
    q = np.array([START, UP, GOAL])
    assert certify_path3d(post, q, 0.02).ok  # the polygon the planner would return
    a = 4.0
    traj, note = plan_timing(post, q, True, max_acceleration=a)
    assert note == "" and traj.kind == "smooth"
    v = traj.max_velocity
    np.testing.assert_allclose(traj.evaluate([0.0, traj.duration])[0], q[[0, -1]], atol=1e-9)
    np.testing.assert_allclose(traj.evaluate(traj.times)[0], q, atol=1e-9)
    t, qs = traj.sample(traj.duration / 4000)
    qd, qdd = finite_differences(t, qs)
    assert np.all(np.abs(qd) <= v * (1 + REL))
    assert np.all(np.abs(qdd) <= a * (1 + 1e-2))  # finite differences of a piecewise C¹ curve
    assert np.max(np.abs(qd) / v) > 0.9 or np.max(np.abs(qdd)) > 0.9 * a  # a limit is reached
    _, qd0, _ = traj.evaluate([0.0, traj.duration])
    np.testing.assert_allclose(qd0, 0.0, atol=1e-9)  # at rest at both ends
    # the curve's own proof is a lower bound of the exact distance at dense samples
    assert 0 < traj.min_distance <= np.min(signed_distance3d(post, qs[::4])) + 1e-9


def test_curve_through_the_post_is_not_certified(post):
    q = np.array([START, GOAL])  # the straight line hits the post
    assert np.min(signed_distance3d(post, np.linspace(q[0], q[1], 50))) < 0
    curve = PchipInterpolator([0.0, 1.0], q, axis=0)
    assert not certify_curve(post, curve).ok
    traj = time_path(q, 1.0, 4.0, post)
    assert traj.kind == "stop" and traj.min_distance is None  # the polygon, at rest at waypoints


def test_cli_json_of_a_smooth_3d_timing(tmp_path, capsys):
    import json

    from gdnplan.cli import run

    problem = tmp_path / "free.toml"
    problem.write_text(
        '[robot]\nname = "ur5e"\n[scene3d]\n[[scene3d.obstacles]]\ntype = "box"\n'
        "size = [0.1, 0.1, 0.1]\nposition = [0.0, 0.8, 0.3]\n"
        f"[start]\nq = {START}\n[goal]\nq = {GOAL}\n"
    )
    with pytest.raises(SystemExit) as exit_:
        run(["plan", str(problem), "--json", "-q", "--max-acceleration", "3"])
    assert exit_.value.code == 0
    out = json.loads(capsys.readouterr().out)
    assert out["timing"] == "smooth" and out["timing_min_distance"] > 0
    t, q = np.array(out["t"]), np.array(out["q"])
    assert t[0] == 0 and t[-1] == out["duration"] and np.all(np.diff(t) > 0)
    np.testing.assert_allclose(q[[0, -1]], [START, GOAL], atol=1e-9)
