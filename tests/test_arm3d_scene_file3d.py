"""3-D problem files: [robot] + [scene3d] tables, rotations, pose goals, bad input, a fuzzer."""

import copy
import math
import tomllib
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
import tomli_w
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from gdnplan.arm3d import Scene3D, load_robot3d, signed_distance3d
from gdnplan.arm3d.scene_file3d import rpy_matrix, scene3d_from_config
from gdnplan.errors import GdnplanError, InfeasibleProblemError, InputError, ProblemFileError
from gdnplan.trajopt import Problem, read_problem_file

ROOT = Path(__file__).resolve().parent.parent
UR5E = read_problem_file(ROOT / "problems" / "ur5e_boxes3d.toml")
BOX = {"type": "box", "size": [0.2, 0.2, 0.2], "position": [0.6, 0.0, 0.3]}


def small(**obstacle) -> dict:
    """A UR5e problem among one obstacle (default BOX), straight line free."""
    return {
        "robot": {"name": "ur5e"},
        "scene3d": {"obstacles": [copy.deepcopy(obstacle or BOX)]},
        "start": {"q": [0.0, -1.57, 1.0, -1.0, 0.0, 0.0]},
        "goal": {"q": [0.4, -1.57, 1.0, -1.0, 0.0, 0.0]},
        "options": {"waypoints": 5, "margin": 0.02},
    }


def test_the_shipped_ur5e_file_is_a_3d_problem():
    problem = Problem.from_toml("ur5e_boxes3d")
    assert isinstance(problem.scene, Scene3D) and problem.scene.robot.dof == 6
    assert len(problem.scene.obstacles) == 20
    assert np.all(problem.upper <= math.pi)


@pytest.mark.parametrize(
    "shape",
    [
        {"type": "sphere", "radius": 0.1},
        {"type": "cylinder", "radius": 0.05, "length": 0.3},
        {"type": "capsule", "radius": 0.05, "length": 0.3},
        {"type": "convex", "points": [[0, 0, 0], [0.1, 0, 0], [0, 0.1, 0], [0, 0, 0.1]]},
    ],
)
def test_every_obstacle_kind_loads_at_its_pose(shape):
    scene = scene3d_from_config(small(**shape, position=[0.6, 0.1, 0.4], rpy=[0.3, 0.2, 0.1]))
    (ob,) = scene.obstacles
    np.testing.assert_allclose(np.asarray(ob.pose.getTranslation()), [0.6, 0.1, 0.4])
    if shape["type"] == "sphere":
        return  # a sphere has no orientation
    np.testing.assert_allclose(
        np.asarray(ob.pose.getRotation()), pin.rpy.rpyToMatrix(0.3, 0.2, 0.1), atol=1e-12
    )


def test_rpy_is_urdfs_convention():
    rng = np.random.default_rng(0)
    for rpy in rng.uniform(-3, 3, (20, 3)):
        np.testing.assert_allclose(rpy_matrix(rpy), pin.rpy.rpyToMatrix(*rpy), atol=1e-12)


@pytest.mark.parametrize(
    ("rpy", "message"),
    [
        ([1e6, 0.0, 0.0], r"within ±1000 rad"),  # was "values beyond 1000 m; use metres"
        ([math.inf, 0.0, 0.0], r"within ±1000 rad"),
        ([math.nan, 0.0, 0.0], r"within ±1000 rad"),
        ([True, 0.0, 0.0], r"expected 3 numbers \(rad\)"),
        ([0.0, 0.0], r"expected 3 numbers \(rad\)"),
        ("0 0 0", r"expected 3 numbers \(rad\)"),
    ],
)
def test_a_bad_rpy_is_named_in_radians(rpy, message):
    with pytest.raises(InputError, match=rf"^rpy: .*{message}") as e:
        rpy_matrix(rpy)
    assert " m;" not in str(e.value)
    with pytest.raises(ProblemFileError, match=message):
        scene3d_from_config(small(**BOX, rpy=rpy))


def test_the_three_rotation_forms_agree():
    r = pin.rpy.rpyToMatrix(0.4, -0.2, 1.1)
    quat = pin.Quaternion(r).coeffs().tolist()  # x, y, z, w
    poses = [
        scene3d_from_config(small(**BOX, **{key: value})).obstacles[0].pose.getRotation()
        for key, value in (("rpy", [0.4, -0.2, 1.1]), ("quaternion", quat), ("matrix", r.tolist()))
    ]
    for pose in poses[1:]:
        np.testing.assert_allclose(np.asarray(pose), np.asarray(poses[0]), atol=1e-9)


def test_a_mesh_file_relative_to_the_problem(tmp_path):
    mesh = tmp_path / "cube.obj"
    corners = [(x, y, z) for x in (0, 0.1) for y in (0, 0.1) for z in (0, 0.1)]
    faces = [(1, 2, 4, 3), (5, 7, 8, 6), (1, 5, 6, 2), (3, 4, 8, 7), (1, 3, 7, 5), (2, 6, 8, 4)]
    mesh.write_text(
        "".join(f"v {x} {y} {z}\n" for x, y, z in corners)
        + "".join("f " + " ".join(map(str, f)) + "\n" for f in faces)
    )
    scene = scene3d_from_config(
        small(type="mesh", file="cube.obj", position=[0.6, 0, 0.3]), tmp_path
    )
    assert len(scene.obstacles) == 1


def test_random_boxes_and_listed_obstacles_add_up():
    cfg = small()
    cfg["scene3d"]["random_boxes"] = {"n": 5, "seed": 2}
    assert len(scene3d_from_config(cfg).obstacles) == 6


@pytest.mark.parametrize(
    "change, message",
    [
        (lambda c: c["robot"].update(name="r2d2"), "unknown 3-D robot 'r2d2'"),
        (
            lambda c: c["scene3d"].update(obstacles=[{"type": "mesh", "file": "nope.stl"}]),
            "nope.stl does not exist",
        ),
        (
            lambda c: c["scene3d"]["obstacles"][0].update(
                matrix=[[1, 0, 0], [0, 1, 0], [0, 0, -1]]
            ),
            "not a rotation matrix",
        ),
        (lambda c: c["scene3d"]["obstacles"][0].update(quaternion=[0, 0, 0, 0]), "zero length"),
        (
            lambda c: c["scene3d"]["obstacles"][0].update(
                rpy=[0, 0],
            ),
            "rpy",
        ),
        (
            lambda c: c["scene3d"]["obstacles"][0].update(rpy=[0, 0, 0], quaternion=[0, 0, 0, 1]),
            "at most one of",
        ),
        (lambda c: c["scene3d"]["obstacles"][0].update(type="cone"), "type: expected one of"),
        (lambda c: c["scene3d"]["obstacles"][0].pop("size"), "size: missing"),
        (lambda c: c["scene3d"].update(colour="red"), "colour"),
        (
            lambda c: c["goal"].update(q=[0.4, -1.57, 1.0, -1.0, 0.0, 9.0]),
            r"goal.q\[5\] = 9 is outside the joint limits",
        ),
        (lambda c: c["goal"].update(position=[0.1, 0.2]), r"\[goal\]: unknown key.*position"),
        (lambda c: c["scene3d"].update(random_boxes={"n": -1}), "random_boxes n"),
    ],
)
def test_bad_input_is_one_error_naming_it(change, message, tmp_path):
    cfg = small()
    change(cfg)
    with pytest.raises(GdnplanError, match=message) as info:
        Problem.from_config(cfg, tmp_path)
    assert "\n" not in str(info.value)


def test_a_mesh_file_that_is_not_a_mesh_is_refused(tmp_path):
    (tmp_path / "junk.stl").write_text("this is not a mesh")
    cfg = small(type="mesh", file="junk.stl", position=[0.6, 0, 0.3])
    with pytest.raises(ProblemFileError, match="not a mesh file"):
        Problem.from_config(cfg, tmp_path)


def test_a_start_in_collision_names_the_pair():
    cfg = small(type="box", size=[0.3, 0.3, 0.3], position=[0.0, 0.0, 0.3])  # around the base
    with pytest.raises(InfeasibleProblemError, match=r"start.q is in collision.* and box0"):
        Problem.from_config(cfg)


def test_a_start_in_self_collision_names_both_links():
    cfg = small()
    cfg["start"]["q"] = [0.0, -1.57, 3.1, 0.0, 0.0, 0.0]  # the forearm folded into the arm
    with pytest.raises(InfeasibleProblemError, match="self-collision"):
        Problem.from_config(cfg)


@pytest.mark.slow  # ~8 s: loads the Panda's meshes, pose IK
def test_a_pose_goal_is_solved_by_ik_clear_of_the_margin():
    problem = Problem.from_toml("panda_shelf3d")
    assert signed_distance3d(problem.scene, problem.goal)[0] > problem.margin
    from gdnplan.arm3d.ik3d import frame_pose

    pose = frame_pose(problem.scene.robot, problem.goal)
    np.testing.assert_allclose(pose.translation, [0.5, 0.0, 0.25], atol=1e-4)


def test_an_unreachable_pose_goal_is_one_line():
    cfg = small()
    del cfg["goal"]["q"]
    cfg["goal"]["pose"] = {"position": [3.0, 0.0, 0.5]}
    with pytest.raises(InfeasibleProblemError, match="out of reach") as info:
        Problem.from_config(cfg)
    assert "\n" not in str(info.value)


scalars = st.one_of(
    st.integers(-(2**63), 2**63 - 1),
    st.floats(allow_nan=True, allow_infinity=True),
    st.sampled_from([0, -1, 1, 1e9, 1e300, math.nan, math.inf, 0.02]),
    st.text(max_size=6),
    st.booleans(),
)
values = st.recursive(
    scalars,
    lambda inner: st.one_of(
        st.lists(inner, max_size=4), st.dictionaries(st.text(max_size=6), inner, max_size=3)
    ),
    max_leaves=10,
)
FIELDS = ["type", "size", "radius", "length", "points", "file", "position", "quaternion",
          "rpy", "matrix", "scale", "name"]  # fmt: skip


@pytest.mark.slow  # ~15 s: every example builds a UR5e problem
@settings(max_examples=100, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    field=st.sampled_from([*FIELDS, "robot", "random_boxes", "start", "goal"]),
    value=values,
)
def test_fuzzed_3d_tables_raise_only_problem_errors(field, value):
    cfg = tomllib.loads(tomli_w.dumps(small()))
    if field == "robot":
        cfg["robot"] = {"name": value}
    elif field == "random_boxes":
        cfg["scene3d"]["random_boxes"] = value if isinstance(value, dict) else {"n": value}
    elif field in ("start", "goal"):
        cfg[field] = {"q": value} if not isinstance(value, dict) else value
    else:
        cfg["scene3d"]["obstacles"][0][field] = value
    try:
        Problem.from_config(cfg)
    except GdnplanError as e:
        assert "\n" not in str(e)


def test_a_user_urdf_with_its_srdf(tmp_path):
    """[robot] urdf (+ srdf, joints, locked), paths relative to the problem file."""
    import shutil

    from gdnplan.assets import robot_urdf

    for suffix in (".urdf", ".srdf"):
        shutil.copy(robot_urdf("ur5e").with_suffix(suffix), tmp_path / f"arm{suffix}")
    cfg = small()
    cfg["robot"] = {
        "urdf": "arm.urdf",
        "srdf": "arm.srdf",
        "joints": list(load_robot3d("ur5e").joint_names),
        "locked": {"left_finger_joint": 0.02, "right_finger_joint": 0.02},
        "contact_only": [["forearm_link", "wrist_2_link"], ["forearm_link", "wrist_3_link"]],
    }
    problem = Problem.from_config(cfg, tmp_path)
    builtin = load_robot3d("ur5e")
    assert problem.scene.robot.contact_only == builtin.contact_only
    assert problem.scene.robot.dof == 6
    assert len(problem.scene.robot.self_pairs) == len(builtin.self_pairs)
    q = np.array(cfg["start"]["q"])
    np.testing.assert_allclose(
        signed_distance3d(problem.scene, q),
        signed_distance3d(Scene3D(builtin, problem.scene.obstacles), q),
    )
