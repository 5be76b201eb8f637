"""3-D robots of gdnplan.arm3d: kinematics, self-collision pairs against the SRDF, bad input."""

from __future__ import annotations

import itertools
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from gdnplan.arm3d import Scene3D, checker3d, load_robot3d, robot3d_from_urdf
from gdnplan.arm3d.builtin import _example_robot_data
from gdnplan.arm3d.pairs import checked_link_pairs
from gdnplan.assets import robot_urdf
from gdnplan.errors import InputError, UnknownNameError


@pytest.fixture(scope="module", params=["ur5e", "panda", "ur5"])
def robot(request):
    return load_robot3d(request.param)


def test_builtin_robots_have_their_joints_and_shapes(robot):
    expected = {"ur5e": (6, "Cylinder"), "panda": (7, "ConvexBase"), "ur5": (6, "ConvexBase")}
    dof, kind = expected[robot.name]
    assert robot.dof == dof and robot.model.nv == dof
    assert kind in {type(s.shape).__name__ for s in robot.shapes}
    assert len(robot.self_pairs) > 0


def test_point_jacobian_matches_finite_differences_of_forward_kinematics(robot):
    rng = np.random.default_rng(1)
    for q in robot.random_configurations(5, rng):
        s = int(rng.integers(len(robot.shapes)))
        local = rng.normal(size=3) * 0.05  # a point in shape s's frame

        def world(qq, s=s, local=local):
            tf = robot.shape_placements(qq)[s]
            return tf[:3, :3] @ local + tf[:3, 3]

        jac = robot.point_jacobian(q, robot.shapes[s].body, world(q))
        h = 1e-6
        fd = np.stack([(world(q + e) - world(q - e)) / (2 * h) for e in np.eye(robot.dof) * h], 1)
        np.testing.assert_allclose(jac, fd, atol=1e-8)


def test_self_collision_pairs_are_the_srdf_complement_pinocchio_computes():
    """Independent truth: Pinocchio's own SRDF reader on the full geometry model."""
    for name in ("panda", "ur5"):
        robot = load_robot3d(name)
        urdf, srdf, _ = _example_robot_data(name)
        model = pin.buildModelFromUrdf(str(urdf))
        dirs = [str(p) for p in urdf.parents]
        geom = pin.buildGeomFromUrdf(
            model, str(urdf), pin.GeometryType.COLLISION, package_dirs=dirs
        )
        geom.addAllCollisionPairs()
        pin.removeCollisionPairs(model, geom, str(srdf))
        link = {i: model.frames[g.parentFrame].name for i, g in enumerate(geom.geometryObjects)}
        pin_pairs = {frozenset((link[p.first], link[p.second])) for p in geom.collisionPairs}
        pin_pairs = {p for p in pin_pairs if len(p) == 2}
        structural = {k for k, why in robot.disabled.items() if why in ("adjacent", "same body")}
        assert checked_link_pairs(robot) == pin_pairs - structural, name
        # and every SRDF pair is unchecked, every unchecked pair has a reason
        assert not checked_link_pairs(robot) & set(robot.disabled)


def test_every_link_pair_is_checked_or_disabled_with_a_reason(robot):
    all_pairs = {frozenset(p) for p in itertools.combinations(robot.links, 2)}
    assert checked_link_pairs(robot) | set(robot.disabled) == all_pairs
    for a, b in (tuple(k) for k in robot.disabled):
        ba = robot.shapes[list(robot.shape_link).index(robot.links.index(a))].body
        bb = robot.shapes[list(robot.shape_link).index(robot.links.index(b))].body
        why = robot.disabled[frozenset((a, b))]
        assert (why == "same body") == (ba == bb)


def test_reference_configurations_are_free_of_self_collision():
    homes = {
        "ur5e": [0.0, -1.57, 1.57, -1.57, -1.57, 0.0],
        "panda": [0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785],  # the SRDF's "default"
        "ur5": [0.0, -1.57, 1.57, -1.57, -1.57, 0.0],
    }
    for name, q in homes.items():
        robot = load_robot3d(name)
        assert checker3d(Scene3D(robot, [])).evaluate(q).distance[0] > 0, name


@pytest.mark.parametrize(
    "q, match",
    [([0.0] * 5, r"shape \(B, 6\)"), ([0.0] * 5 + [np.nan], "NaN"), ("abc", "numbers|shape")],
)
def test_bad_configurations_are_one_line_input_errors(q, match):
    scene = Scene3D(load_robot3d("ur5e"), [])
    with pytest.raises(InputError, match=match) as e:
        checker3d(scene).evaluate(q)
    assert "\n" not in str(e.value)


HOSTILE_Q = st.one_of(
    st.sampled_from(
        [
            [0.0] * 5,
            [0.1] * 6 + [0.0],
            np.zeros((2, 6)),
            np.zeros((1, 6, 1)),
            np.full(6, 0.1 + 1j),
            np.full(6, np.nan),
            np.full(6, True),
            "abcdef",
            [[0.1] * 6, [0.1] * 5],
            np.zeros(6, dtype=object),
        ]
    ),
    st.lists(st.floats(allow_nan=True, allow_infinity=True), min_size=6, max_size=6),
)


@settings(max_examples=60, deadline=None)
@given(q=HOSTILE_Q, method=st.sampled_from(["body_placements", "shape_placements",
                                            "joint_jacobians"]))  # fmt: skip
def test_kinematics_of_one_configuration_check_it(q, method):
    """Pinocchio raised its own ValueError or ArgumentError for a wrong size or a batch, numpy
    dropped a complex q's imaginary part and NaN gave NaN placements: now InputError naming q,
    or finite placements of one real configuration."""
    robot = load_robot3d("ur5e")
    try:
        out = getattr(robot, method)(q)
    except InputError as e:
        assert str(e).startswith("q: ")
        return
    arrays = out if isinstance(out, tuple) else (out,)
    assert all(np.isfinite(a).all() for a in arrays)
    assert np.asarray(q).dtype.kind in "if" and np.asarray(q).size == 6


def test_point_jacobian_and_sampling_check_their_arguments():
    robot, q = load_robot3d("ur5e"), np.zeros(6)
    with pytest.raises(InputError, match=r"^body: expected an integer in \[0, 6\], got 99"):
        robot.point_jacobian(q, 99, [0.0, 0.0, 0.0])
    with pytest.raises(InputError, match=r"^point: expected shape \(B, 3\)"):
        robot.point_jacobian(q, 1, [0.0, 0.0])
    with pytest.raises(InputError, match=r"^n: expected an integer in \[0, 100000000\]"):
        robot.random_configurations(-1, np.random.default_rng(0))
    with pytest.raises(InputError, match=r"^rng: expected a numpy.random.Generator, got int"):
        robot.random_configurations(3, 0)
    with pytest.raises(InputError, match=r"^tol: expected a finite number ≥ 0, got nan"):
        robot.within_limits(q, tol=np.nan)  # every configuration was "outside"
    with pytest.raises(InputError, match=r"^urdf: expected a file path, got int"):
        robot3d_from_urdf(3)


URDF = """<robot name="r">
  <link name="a"><collision><geometry>{geometry}</geometry></collision></link>
  <link name="b"><collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision></link>
  <joint name="j" type="revolute"><parent link="a"/><child link="b"/>
    <origin xyz="0 0 0.5"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
</robot>"""


def test_a_user_urdf_with_a_missing_mesh_or_a_flat_box_is_an_input_error(tmp_path):
    ok = tmp_path / "ok.urdf"
    ok.write_text(URDF.format(geometry='<sphere radius="0.1"/>'))
    robot = robot3d_from_urdf(ok)
    assert robot.dof == 1 and robot.links == ("a", "b") and robot.disabled
    missing = tmp_path / "missing.urdf"
    missing.write_text(URDF.format(geometry='<mesh filename="nowhere.stl"/>'))
    with pytest.raises((InputError, UnknownNameError)) as e:
        robot3d_from_urdf(missing)
    assert "\n" not in str(e.value)
    flat = tmp_path / "flat.urdf"
    flat.write_text(URDF.format(geometry='<box size="0.1 0.1 0"/>'))
    with pytest.raises(InputError, match="size"):
        robot3d_from_urdf(flat)


def test_unknown_names_and_joint_order(tmp_path):
    with pytest.raises(UnknownNameError, match="choose one of"):
        load_robot3d("kuka")
    with pytest.raises(UnknownNameError, match="not a joint"):
        robot3d_from_urdf(robot_urdf("ur5e"), joints=["shoulder_pan_joint", "nope"])
    with pytest.raises(InputError, match="URDF's order"):
        robot3d_from_urdf(robot_urdf("ur5e"), joints=["elbow_joint", "shoulder_pan_joint"])
    with pytest.raises(InputError, match="not a revolute"):
        robot3d_from_urdf(robot_urdf("ur5e"), joints=["left_finger_joint"])
    srdf = tmp_path / "other.srdf"
    srdf.write_text('<robot><disable_collisions link1="x" link2="base_link"/></robot>')
    with pytest.raises(InputError, match="link 'x'"):
        robot3d_from_urdf(robot_urdf("ur5e"), srdf=srdf)


ARM = Path(__file__).resolve().parent.parent / "examples" / "three_link_arm.urdf"


@pytest.mark.parametrize("angle", [-2.5, 0.0, 1.0, 3.0, 7.0])
def test_a_locked_continuous_joint_sits_where_planning_it_would_put_it(angle):
    """three_link_arm's continuous wrist locked at an angle places every shape as the robot
    that plans the wrist does at that angle (Pinocchio stores it as cos θ, sin θ)."""
    from gdnplan.arm3d.fk3d import shape_placements_batch

    roll = {"tool_roll": 0.5}
    locked = robot3d_from_urdf(ARM, joints=["shoulder", "elbow"], locked={"wrist": angle, **roll})
    planned = robot3d_from_urdf(ARM, joints=["shoulder", "elbow", "wrist"], locked=roll)
    wrapped = np.arctan2(np.sin(angle), np.cos(angle))  # the planned wrist lives in [−π, π]
    a = shape_placements_batch(locked, np.array([[0.3, -0.2]]))
    b = shape_placements_batch(planned, np.array([[0.3, -0.2, wrapped]]))
    assert np.allclose(a, b, atol=1e-12)


@pytest.mark.parametrize("value", [float("nan"), float("inf")])
def test_a_non_finite_locked_value_is_refused_as_such(value):
    with pytest.raises(InputError, match="'wrist' needs a finite number"):
        robot3d_from_urdf(ARM, joints=["shoulder", "elbow"], locked={"wrist": value})


UR5E_ARM = ("shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint")
UR5E_WRIST = ("wrist_1_joint", "wrist_2_joint", "wrist_3_joint")


@settings(max_examples=6, deadline=None)
@given(st.lists(st.floats(-3.0, 3.0), min_size=3, max_size=3), st.integers(0, 2**31))
def test_locked_joints_never_hide_a_self_collision(wrist, seed):
    """The UR5e planning its arm with the wrist locked: every pair of links a locked joint
    separates (the gripper against the upper arm, say) is checked; so wherever the pairwise
    distances of all non-adjacent URDF links show a self-collision, so does the robot's."""
    urdf = robot_urdf("ur5e")
    locked = dict(zip(UR5E_WRIST, wrist, strict=True))
    robot = robot3d_from_urdf(
        urdf, joints=list(UR5E_ARM), locked=locked, srdf=urdf.with_suffix(".srdf")
    )
    adjacent = {k for k, why in robot.disabled.items() if why in ("adjacent", "same body")}
    assert frozenset(("upper_arm_link", "gripper_base_link")) not in adjacent
    # every adjacent pair is joined by one movable URDF joint, a planning one (fixed ones aside)
    up = {}  # child link -> (parent link, joint name, joint type)
    for j in ET.parse(urdf).getroot().iter("joint"):
        up[j.find("child").get("link")] = (
            j.find("parent").get("link"),
            j.get("name"),
            j.get("type"),
        )

    def movable_to_root(link):
        chain = []
        while link in up:
            link, name, kind = up[link]
            chain += [] if kind == "fixed" else [name]
        return chain

    for a, b in (tuple(k) for k, why in robot.disabled.items() if why == "adjacent"):
        between = set(movable_to_root(a)) ^ set(movable_to_root(b))
        assert len(between) == 1 and between <= set(UR5E_ARM), (a, b, between)
    q = np.random.default_rng(seed).uniform(robot.lower, robot.upper, (40, robot.dof))
    d = checker3d(Scene3D(robot, [])).evaluate(q).distance
    # the same robot with the wrist planned, at the locked values: its pairs that the lock
    # does not freeze (links on two bodies of the locked robot) give the same minimum
    full = robot3d_from_urdf(
        urdf, joints=list(UR5E_ARM + UR5E_WRIST), srdf=urdf.with_suffix(".srdf")
    )
    table = checker3d(Scene3D(full, []))
    body = {s.link: s.body for s in robot.shapes}
    moving = [body[a.split("/")[0]] != body[b.split("/")[0]] for a, b in table.pair_names()]
    d_pairs, _ = table.pair_distances(np.c_[q, np.tile(wrist, (len(q), 1))])
    assert np.allclose(d, d_pairs[:, moving].min(axis=1), atol=1e-9)


def test_a_robot3d_is_immutable_once_built():
    """Motion bounds and checkers are cached per robot object and load_robot3d hands every
    caller the same one: neither attributes nor arrays can change under them."""
    from gdnplan.arm3d import load_robot3d

    robot = load_robot3d("ur5e")
    for name in ("shapes", "model", "lower", "self_pairs", "contact_only", "new_attribute"):
        with pytest.raises(AttributeError, match="immutable"):
            setattr(robot, name, None)
    for array in (robot.lower, robot.upper, robot.self_pairs, robot.shape_link):
        with pytest.raises(ValueError, match="read-only"):
            array[0] = array[0]
    assert load_robot3d("ur5e") is robot and robot.lower.flags.writeable is False


def test_names_and_paths_of_the_wrong_kind_are_gdnplan_errors():
    """A list name raised TypeError (unhashable), an int path TypeError (Path(3)), tool_frame
    of None AttributeError."""
    from gdnplan.arm3d import mesh_obstacle, read_cloud, tool_frame

    with pytest.raises(UnknownNameError, match=r"^robot: unknown 3-D robot \['ur5e'\]"):
        load_robot3d(["ur5e"])
    with pytest.raises(InputError, match=r"^robot: expected a Robot3D, got NoneType"):
        tool_frame(None)
    with pytest.raises(InputError, match=r"^cloud: point file: expected a file path, got int"):
        read_cloud(3)
    with pytest.raises(InputError, match=r"^mesh: mesh file: expected a file path, got int"):
        mesh_obstacle(3)
