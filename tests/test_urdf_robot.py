"""Robots from URDF files: the user arm's kinematics, and every refusal of a robot that cannot
be planned in its plane (missing or broken URDF, unknown, prismatic, branched or tilted
joints, degenerate plane axes, nothing to collide with)."""

from __future__ import annotations

import tempfile
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

import gdnplan as gp
from gdnplan.errors import InputError, UnknownNameError
from gdnplan.urdf_robot import AXIS_TOLERANCE, RobotSpec, plane_basis, robot_from_urdf

ROOT = Path(__file__).resolve().parent.parent
ARM = ROOT / "examples" / "three_link_arm.urdf"
ARM_JOINTS = ("shoulder", "elbow", "wrist")
LIMIT = '<limit lower="-3" upper="3" effort="1" velocity="1"/>'


def link(name: str, length: float = 0.4, width: float = 0.05) -> str:
    box = f'<box size="{length} {width} {width}"/>'
    geometry = f'<collision><origin xyz="{length / 2} 0 0"/><geometry>{box}</geometry></collision>'
    return f'<link name="{name}">{geometry}</link>'


def joint(name, parent, child, kind="revolute", xyz="0 0 0", rpy="0 0 0", axis="0 0 1") -> str:
    limit = LIMIT if kind in ("revolute", "prismatic") else ""
    return (
        f'<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>'
        f'<origin xyz="{xyz}" rpy="{rpy}"/><axis xyz="{axis}"/>{limit}</joint>'
    )


def write_urdf(folder: Path, *parts: str, name: str = "test_arm") -> Path:
    path = folder / f"{name}.urdf"
    path.write_text(f'<?xml version="1.0"?><robot name="{name}">{"".join(parts)}</robot>')
    return path


def two_link(folder: Path, kind2: str = "revolute", axis2: str = "0 0 1") -> Path:
    return write_urdf(
        folder,
        '<link name="base"/>',
        joint("j1", "base", "l1"),
        link("l1"),
        joint("j2", "l1", "l2", kind=kind2, xyz="0.4 0 0", axis=axis2),
        link("l2"),
    )


def arm_spec(**changes) -> RobotSpec:
    base = {"urdf": ARM, "planning_joints": ARM_JOINTS, "locked": {"tool_roll": np.pi / 2}}
    return RobotSpec(**{**base, **changes})


# -------------------------------------------------------------------- the user arm
def test_user_arm_kinematics_equal_pinocchio():
    arm = gp.robot_from_urdf("arm", arm_spec())
    assert arm.name == "arm" and arm.joint_names == list(ARM_JOINTS)
    q = arm.sample(20, seed=3)
    np.testing.assert_allclose(arm.node_positions(q), arm.node_positions_pinocchio(q), atol=1e-12)
    np.testing.assert_allclose(arm.node_jacobians(q), arm.node_jacobians_pinocchio(q), atol=1e-12)


def test_continuous_wrist_is_planned_within_pi_and_locked_roll_flattens_the_tool():
    arm = gp.robot_from_urdf("arm", arm_spec())
    assert arm.lower[2] == pytest.approx(-np.pi) and arm.upper[2] == pytest.approx(np.pi)
    tool = next(p for p in arm.polygons if p.name.startswith("tool"))
    width = np.ptp(tool.vertices0[:, 1])
    assert width == pytest.approx(0.02, abs=1e-6)  # rolled by π/2: the 0.02 m side in plane
    unrolled = gp.robot_from_urdf("arm", arm_spec(locked={}))
    tool0 = next(p for p in unrolled.polygons if p.name.startswith("tool"))
    assert np.ptp(tool0.vertices0[:, 1]) == pytest.approx(0.08, abs=1e-6)


def test_public_api():
    assert gp.RobotSpec is RobotSpec and gp.robot_from_urdf is robot_from_urdf


@pytest.mark.parametrize("name", ["planar2", "ur5e", "", 3])
def test_shipped_or_empty_names_are_refused(name):
    with pytest.raises(InputError, match="name"):
        gp.robot_from_urdf(name, arm_spec())


# -------------------------------------------------------------------- broken files
def test_missing_urdf(tmp_path):
    with pytest.raises(UnknownNameError, match=r"nope\.urdf does not exist"):
        gp.robot_from_urdf("arm", arm_spec(urdf=tmp_path / "nope.urdf"))


@pytest.mark.parametrize(
    ("text", "reason"),
    [
        ("this is not xml", "not a readable XML file"),
        ("", "not a readable XML file"),
        ('<robot name="x"><link name="a"/>' + joint("j", "a", "b", "revolute")[:-8], "XML"),
        (  # valid XML, invalid URDF: urdfdom's own complaint becomes the message
            '<robot name="x"><link name="a"/><link name="b"/><joint name="j" type="revolute">'
            '<parent link="a"/><child link="b"/></joint></robot>',
            "does not specify limits",
        ),
    ],
)
def test_garbage_urdf_is_one_input_error(tmp_path, capfd, text, reason):
    path = tmp_path / "bad.urdf"
    path.write_text(text)
    with pytest.raises(InputError, match=reason) as info:
        gp.robot_from_urdf("arm", arm_spec(urdf=path))
    assert "\n" not in str(info.value) and str(path) in str(info.value)
    assert "Error" not in capfd.readouterr().err  # urdfdom's stderr lines are captured


# -------------------------------------------------------------------- joints
def test_unknown_planning_joint_lists_the_joints():
    with pytest.raises(UnknownNameError, match=r"'knee' is not in three_link_arm\.urdf.*'elbow'"):
        gp.robot_from_urdf("arm", arm_spec(planning_joints=("shoulder", "knee")))


def test_unknown_locked_joint():
    with pytest.raises(UnknownNameError, match="locked: joint 'roll'"):
        gp.robot_from_urdf("arm", arm_spec(locked={"roll": 0.0}))


def test_a_joint_both_planned_and_locked():
    with pytest.raises(InputError, match="'wrist' is a planning joint"):
        gp.robot_from_urdf("arm", arm_spec(locked={"wrist": 0.0}))


def test_prismatic_planning_joint_is_named(tmp_path):
    spec = RobotSpec(urdf=two_link(tmp_path, kind2="prismatic"), planning_joints=("j1", "j2"))
    with pytest.raises(InputError, match="'j2' is prismatic"):
        gp.robot_from_urdf("arm", spec)


def test_branched_joints_are_not_a_serial_chain(tmp_path):
    path = write_urdf(
        tmp_path,
        '<link name="base"/>',
        joint("j1", "base", "l1"),
        link("l1"),
        joint("j2", "base", "l2", xyz="0 0.3 0"),  # a sibling of j1, not its child
        link("l2"),
    )
    with pytest.raises(InputError, match=r"'j2' does not hang from 'j1'.*serial chain"):
        gp.robot_from_urdf("arm", RobotSpec(urdf=path, planning_joints=("j1", "j2")))


def test_planning_joints_listed_tip_first_are_refused():
    with pytest.raises(InputError, match="base to tip"):
        gp.robot_from_urdf("arm", arm_spec(planning_joints=("elbow", "shoulder", "wrist")))


def test_joint_axis_in_the_plane_is_named(tmp_path):
    spec = RobotSpec(urdf=two_link(tmp_path, axis2="0 1 0"), planning_joints=("j1", "j2"))
    with pytest.raises(InputError, match="planning joint 'j2' turns about the world axis"):
        gp.robot_from_urdf("arm", spec)


def test_ur5_with_the_default_plane_is_refused_naming_shoulder_lift():
    """The class of bug: UR5's lift joints turn about world y; in the default x–y plane they
    would move nothing, and the robot used to load."""
    example_robot_data = pytest.importorskip("example_robot_data")
    from gdnplan.ur5e import PLANNING_JOINTS

    urdf = Path(example_robot_data.load("ur5").urdf)
    spec = RobotSpec(urdf=urdf, planning_joints=PLANNING_JOINTS)
    with pytest.raises(InputError, match="planning joint 'shoulder_lift_joint' turns about"):
        gp.robot_from_urdf("my_ur5", spec)
    # the plane of the shipped ur5 (x–z) is accepted, from the file (meshes via package://)
    robot = gp.robot_from_urdf(
        "my_ur5",
        RobotSpec(
            urdf=urdf,
            planning_joints=PLANNING_JOINTS,
            locked={"wrist_2_joint": np.pi / 2},
            plane_axes=((1, 0, 0), (0, 0, 1)),
        ),
    )
    assert robot.dof == 3 and robot.n_links > 0


@pytest.mark.parametrize("name", ["planar2", "planar7", "ur5e", "ur5"])
def test_shipped_robots_turn_about_their_plane_normal(name):
    robot = gp.load_robot(name)
    data = robot.model.createData()
    pin.forwardKinematics(robot.model, data, np.zeros(robot.dof))
    for j in range(1, robot.dof + 1):
        z = (
            data.oMi[j].rotation
            @ np.eye(3)[
                ["JointModelRX", "JointModelRY", "JointModelRZ"].index(
                    robot.model.joints[j].shortname()
                )
            ]
        )
        assert abs(abs(z @ robot.plane.normal) - 1) < 1e-12


# -------------------------------------------------------------------- plane and geometry
@pytest.mark.parametrize(
    ("axes", "message"),
    [
        (((1, 0, 0), (1, 0, 0)), "not perpendicular"),
        (((1, 0, 0), (1, 1, 0)), "not perpendicular"),
        (((1, 0, 0), (0, 0, 0)), "nonzero"),
        (((1, 0, 0), (0, float("nan"), 1)), "finite"),
        (((1, 0, 0),), "two 3-vectors"),
        (((1, 0), (0, 1)), "two 3-vectors"),
        ((("x", 0, 0), (0, 1, 0)), "two 3-vectors"),
        (((True, 0, 0), (0, 1, 0)), "two 3-vectors"),
    ],
)
def test_degenerate_plane_axes(axes, message):
    with pytest.raises(InputError, match=f"plane: .*{message}"):
        gp.robot_from_urdf("arm", arm_spec(plane_axes=axes))


def test_plane_basis_is_orthonormal_and_keeps_u():
    basis = plane_basis(((2, 0, 0), (0.0005, 3, 0)))
    np.testing.assert_allclose(basis @ basis.T, np.eye(2), atol=1e-15)
    np.testing.assert_allclose(basis[0], (1, 0, 0))


def test_no_geometry_and_no_polygons(tmp_path):
    path = write_urdf(
        tmp_path, '<link name="base"/>', joint("j1", "base", "l1"), '<link name="l1"/>'
    )
    with pytest.raises(InputError, match="no collision geometry"):
        gp.robot_from_urdf("arm", RobotSpec(urdf=path, planning_joints=("j1",)))
    square = np.array([[0.1, -0.02], [0.3, -0.02], [0.3, 0.02], [0.1, 0.02]])
    robot = gp.robot_from_urdf(
        "arm", RobotSpec(urdf=path, planning_joints=("j1",)), extra_polygons=[("p", "l1", square)]
    )
    assert robot.n_links == 1 and robot.polygons[0].body == 1


@pytest.mark.parametrize(
    ("size", "match"),
    [
        ("0.4 0 0.05", r"link 'l1' <collision> 1 <box size>: '0.4 0 0.05' has a size outside"),
        ("0.4 1.5e-6 0.05", r"'l1_0' of test_arm\.urdf projects to a segment"),
    ],
)
def test_geometry_flat_in_the_plane_is_refused(tmp_path, size, match):
    flat = f'<collision><geometry><box size="{size}"/></geometry></collision>'
    path = write_urdf(
        tmp_path, '<link name="base"/>', joint("j1", "base", "l1"), f'<link name="l1">{flat}</link>'
    )
    with pytest.raises(InputError, match=match):
        gp.robot_from_urdf("arm", RobotSpec(urdf=path, planning_joints=("j1",)))


@pytest.mark.parametrize(("field", "value"), [("max_vertices", 2), ("base_radius", -0.1)])
def test_bad_spec_numbers(field, value):
    with pytest.raises(InputError, match=field):
        gp.robot_from_urdf("arm", arm_spec(**{field: value}))


# -------------------------------------------------------------------- any plane orientation
def rotation(rpy) -> np.ndarray:
    return pin.rpy.rpyToMatrix(*rpy)


@settings(max_examples=25, deadline=None)
@given(
    rpy=st.tuples(*[st.floats(-np.pi, np.pi)] * 3),
    lengths=st.tuples(st.floats(0.1, 1.0), st.floats(0.1, 1.0)),
    tilt=st.floats(10 * AXIS_TOLERANCE, 1.0),
)
def test_arm_in_any_plane_is_accepted_and_a_tilted_plane_refused(rpy, lengths, tilt):
    """A two-link arm mounted with any rotation R (a fixed joint): plane axes R x, R y are
    accepted and its chain equals Pinocchio; the plane tilted by more than the tolerance about
    u is refused naming joint j1; tilted by far less, accepted."""
    with tempfile.TemporaryDirectory() as folder:
        path = write_urdf(
            Path(folder),
            '<link name="world"/>',
            joint(
                "mount",
                "world",
                "base",
                kind="fixed",
                xyz="0.1 -0.2 0.3",
                rpy=" ".join(repr(a) for a in rpy),
            ),
            '<link name="base"/>',
            joint("j1", "base", "l1"),
            link("l1", lengths[0]),
            joint("j2", "l1", "l2", xyz=f"{lengths[0]} 0 0"),
            link("l2", lengths[1]),
        )
        r = rotation(rpy)
        spec = RobotSpec(urdf=path, planning_joints=("j1", "j2"), plane_axes=(r[:, 0], r[:, 1]))
        robot = gp.robot_from_urdf("arm", spec)
        q = robot.sample(5, seed=0)
        np.testing.assert_allclose(
            robot.node_positions(q), robot.node_positions_pinocchio(q), atol=1e-10
        )
        assert robot.reach == pytest.approx(sum(lengths), abs=1e-9 + 0.03)
        c, s = np.cos(tilt), np.sin(tilt)
        tilted = (r[:, 0], c * r[:, 1] + s * r[:, 2])
        with pytest.raises(InputError, match="planning joint 'j1' turns about"):
            gp.robot_from_urdf(
                "arm", RobotSpec(urdf=path, planning_joints=("j1", "j2"), plane_axes=tilted)
            )
        slight = (r[:, 0], np.cos(1e-9) * r[:, 1] + np.sin(1e-9) * r[:, 2])
        gp.robot_from_urdf(
            "arm", RobotSpec(urdf=path, planning_joints=("j1", "j2"), plane_axes=slight)
        )


def mimic_arm(folder: Path) -> Path:
    """j1 → j2 → j3 about z; j2 mimics j1 (a parallel linkage: j2 = 2 j1 + 0.1)."""
    j2 = joint("j2", "l1", "l2", xyz="0.4 0 0").replace(
        "</joint>", '<mimic joint="j1" multiplier="2" offset="0.1"/></joint>'
    )
    return write_urdf(
        folder,
        '<link name="base"/>',
        joint("j1", "base", "l1"),
        link("l1"),
        j2,
        link("l2"),
        joint("j3", "l2", "l3", xyz="0.4 0 0"),
        link("l3"),
    )


@pytest.mark.parametrize("planning", [("j1",), ("j2",), ("j1", "j2"), ("j1", "j2", "j3"), None])
@pytest.mark.parametrize("kind", ["planar", "3d"])
def test_a_planning_joint_in_a_mimic_pair_is_refused(tmp_path, planning, kind):
    """Pinocchio reads a <mimic> joint as independent: planning either joint of the pair would
    plan (and certify) another robot than the URDF's, so the loaders refuse it by name."""
    from gdnplan.arm3d import robot3d_from_urdf

    path = mimic_arm(tmp_path)
    with pytest.raises(InputError, match="'j2' mimics joint 'j1'"):
        if kind == "planar":
            spec = RobotSpec(urdf=path, planning_joints=planning or ("j1", "j2", "j3"))
            robot_from_urdf("mimic_arm", spec)
        else:
            robot3d_from_urdf(path, joints=planning)


@pytest.mark.parametrize("kind", ["planar", "3d"])
def test_a_locked_mimic_pair_still_loads(tmp_path, kind):
    from gdnplan.arm3d import robot3d_from_urdf

    path = mimic_arm(tmp_path)
    if kind == "planar":
        spec = RobotSpec(urdf=path, planning_joints=("j3",), locked={"j1": 0.2, "j2": 0.5})
        assert robot_from_urdf("mimic_arm", spec).dof == 1
    else:
        assert robot3d_from_urdf(path, joints=["j3"], locked={"j1": 0.2, "j2": 0.5}).dof == 1


@pytest.mark.parametrize("axis", ["0 0 0", "0 0 1e-300", "1e-200 1e-200 0", "0 0 -1e-310"])
@pytest.mark.parametrize("kind", ["planar", "3d"])
def test_a_joint_axis_that_is_no_direction_is_refused(tmp_path, axis, kind):
    """Pinocchio keeps a zero axis (the joint never moves) and one too small to normalise (its
    "rotations" scale and shear links): both loaders refuse them, naming the joint."""
    from gdnplan.arm3d import robot3d_from_urdf

    path = two_link(tmp_path, axis2=axis)
    with pytest.raises(InputError, match=r"joint 'j2' .* not a direction"):
        if kind == "planar":
            robot_from_urdf("axis_arm", RobotSpec(urdf=path, planning_joints=("j1", "j2")))
        else:
            robot3d_from_urdf(path)


@settings(max_examples=25, deadline=None)
@given(
    st.lists(st.floats(-1.0, 1.0), min_size=3, max_size=3).filter(
        lambda a: np.linalg.norm(a) > 1e-3
    ),
    st.sampled_from([1e-12, 1e-3, 1.0, 7.5, 1e9]),
)
def test_any_nonzero_joint_axis_acts_as_its_unit_direction(direction, scale):
    """A 3-D arm's joint turns about axis / |axis| whatever the length the URDF gives."""
    from gdnplan.arm3d import robot3d_from_urdf
    from gdnplan.arm3d.fk3d import body_placements_batch

    with tempfile.TemporaryDirectory() as folder:
        axis = " ".join(repr(x * scale) for x in direction)
        robot = robot3d_from_urdf(two_link(Path(folder), axis2=axis))
    q = np.array([[0.3, 1.1]])
    rotation = body_placements_batch(robot, q)[0, 2, :3, :3]
    unit = np.asarray(direction) / np.linalg.norm(direction)
    expected = (
        pin.AngleAxis(0.3, np.array([0.0, 0.0, 1.0])).matrix() @ pin.AngleAxis(1.1, unit).matrix()
    )
    assert np.allclose(rotation, expected, atol=1e-9)


def far_origins(folder: Path, out: str, back: str, collision: str = "0 0 0") -> Path:
    """j1 about z, then fixed joints ``out`` and ``back`` along x, a box at ``collision``."""
    box = f'<collision><origin xyz="{collision}"/><geometry><box size="0.1 0.1 0.1"/></geometry>'
    return write_urdf(
        folder,
        '<link name="base"/>',
        joint("j1", "base", "l1"),
        '<link name="l1"/>',
        joint("out", "l1", "l2", kind="fixed", xyz=f"{out} 0 0"),
        '<link name="l2"/>',
        joint("back", "l2", "l3", kind="fixed", xyz=f"{back} 0 0"),
        f'<link name="l3">{box}</collision></link>',
    )


@pytest.mark.parametrize(
    "out, back, collision",
    [
        ("1e20", "-99999999999999999999.4", "0 0 0"),  # the box is 0.6 m out; doubles say 0
        ("1e300", "0", "0 0 0"),
        ("0.3", "0.3", "0 0 1e300"),
        ("1000.5", "-1000", "0 0 0"),
    ],
)
@pytest.mark.parametrize("kind", ["planar", "3d"])
def test_an_origin_beyond_a_kilometre_is_refused(tmp_path, out, back, collision, kind):
    """Far origins lose links' positions to rounding (or overflow coal): refused by name."""
    from gdnplan.arm3d import robot3d_from_urdf

    path = far_origins(tmp_path, out, back, collision)
    with pytest.raises(InputError, match=r"origin of .* beyond 1000 m"):
        if kind == "planar":
            robot_from_urdf("far_arm", RobotSpec(urdf=path, planning_joints=("j1",)))
        else:
            robot3d_from_urdf(path)


def test_origins_within_a_kilometre_still_load(tmp_path):
    from gdnplan.arm3d import robot3d_from_urdf

    robot = robot3d_from_urdf(far_origins(tmp_path, "999.5", "-999", "0 0 0.1"))
    assert robot.dof == 1


@pytest.mark.parametrize("kind", ["planar", "3d"])
@pytest.mark.parametrize("j1", [-0.4, 0.0, 0.2, 1.3])
def test_a_locked_mimic_follower_follows_its_master(tmp_path, kind, j1):
    """Unlisted, j2 sits at 2 j1 + 0.1 (as on the real robot); listed elsewhere, refused."""
    from gdnplan.arm3d import robot3d_from_urdf
    from gdnplan.arm3d.fk3d import shape_placements_batch

    path = mimic_arm(tmp_path)

    def build(locked):
        if kind == "planar":
            spec = RobotSpec(urdf=path, planning_joints=("j3",), locked=locked)
            return robot_from_urdf("mimic_arm", spec)
        return robot3d_from_urdf(path, joints=["j3"], locked=locked)

    follows, explicit = build({"j1": j1}), build({"j1": j1, "j2": 2 * j1 + 0.1})
    q = np.array([[0.7]])
    if kind == "planar":
        assert np.allclose(follows.link_polygons(q[0])[-1], explicit.link_polygons(q[0])[-1])
    else:
        assert np.allclose(shape_placements_batch(follows, q), shape_placements_batch(explicit, q))
    with pytest.raises(InputError, match="'j2' mimics 'j1'"):
        build({"j1": j1, "j2": 2 * j1 + 0.2})


def mimic_tree(folder: Path, masters, kinds, order, mimic: bool = True) -> Path:
    """j1 (planned, about z) → m0 → m1 → … a chain of locked joints about y (link k_i after
    m_i); m_i (i ≥ 1)
    mimics m_{masters[i-1]} (2 m + 0.1, an earlier joint), ``kinds`` revolute or continuous;
    the joints are written in the permutation ``order`` of the chain."""
    limit = '<limit lower="-100" upper="100" effort="1" velocity="1"/>'
    parts = ['<link name="base"/>', joint("j1", "base", "l1"), link("l1")]
    chain = []
    for i, kind in enumerate(["revolute", *kinds]):
        parent = "l1" if i == 0 else f"k{i - 1}"
        tag = joint(f"m{i}", parent, f"k{i}", kind=kind, xyz="0.4 0 0", axis="0 1 0")
        tag = tag.replace(LIMIT, limit)
        if i and mimic:
            tag = tag.replace(
                "</joint>",
                f'<mimic joint="m{masters[i - 1]}" multiplier="2" offset="0.1"/></joint>',
            )
        chain.append(tag)
        parts.append(link(f"k{i}", length=0.3))
    name = "mimic_tree" if mimic else "plain_tree"
    return write_urdf(folder, *parts, *(chain[k] for k in order), name=name)


@st.composite
def mimic_trees(draw):
    n = draw(st.integers(1, 4))
    masters = [draw(st.integers(0, i)) for i in range(n)]
    kinds = draw(st.lists(st.sampled_from(["revolute", "continuous"]), min_size=n, max_size=n))
    order = draw(st.permutations(range(n + 1)))
    return masters, kinds, order, draw(st.floats(-1.0, 1.0))


@settings(max_examples=40, deadline=None)
@given(mimic_trees())
@example(([0, 1], ["revolute", "continuous"], [2, 1, 0], 0.5))  # the audit's chain, reversed
@example(([0], ["continuous"], [0, 1], 1.0))  # a continuous follower stayed at 0
def test_locked_mimic_chains_follow_their_masters_in_any_file_order(tree):
    """Every locked <mimic> follower sits at 2 · master + 0.1, its master's final value, also
    when the master is itself a follower written later in the file, and for continuous joints
    (a follower of a follower, or a continuous follower, used to stay at 0: the arm certified
    was not the URDF's)."""
    from gdnplan.arm3d import robot3d_from_urdf
    from gdnplan.arm3d.fk3d import shape_placements_batch

    masters, kinds, order, m0 = tree
    values = [m0]
    for master in masters:
        values.append(2 * values[master] + 0.1)
    with tempfile.TemporaryDirectory() as folder:
        follows = robot3d_from_urdf(
            mimic_tree(Path(folder), masters, kinds, order), joints=["j1"], locked={"m0": m0}
        )
        locked = {f"m{i}": v for i, v in enumerate(values)}
        plain = mimic_tree(Path(folder), masters, kinds, order, mimic=False)
        explicit = robot3d_from_urdf(plain, joints=["j1"], locked=locked)
    q = np.array([[0.7]])
    assert np.allclose(shape_placements_batch(follows, q), shape_placements_batch(explicit, q))


@pytest.mark.parametrize(
    "mimic, match",
    [('<mimic joint="nope"/>', "names 'nope', not a joint"), ('<mimic joint="m1"/>', "cycle")],
)
def test_a_mimic_of_no_joint_or_a_mimic_cycle_is_refused(tmp_path, mimic, match):
    from gdnplan.arm3d import robot3d_from_urdf

    path = mimic_tree(tmp_path, [0], ["revolute"], [0, 1])  # m1 mimics m0
    text = path.read_text()
    m0 = text.index('<joint name="m0"')
    end = text.index("</joint>", m0)
    path.write_text(text[:end] + mimic + text[end:])
    with pytest.raises(InputError, match=match):
        robot3d_from_urdf(path, joints=["j1"])


@settings(max_examples=20, deadline=None)
@given(
    st.sampled_from(["j1", "j2"]),
    st.sampled_from(["base", "l1", "l2"]),
    st.sampled_from(["revolute", "fixed"]),
    st.sampled_from(["planar", "3d"]),
)
@example("j1", "l1", "revolute", "3d")  # the audit's case: exit 3, ValueError from Pinocchio
def test_a_joint_named_as_a_link_is_refused(joint_name, link_name, kind2, loader):
    """URDF allows a joint and a link of one name; Pinocchio's reduced model then raised a
    ValueError ("Several frames match the filter"): both loaders refuse it by name."""
    from gdnplan.arm3d import robot3d_from_urdf

    with tempfile.TemporaryDirectory() as folder:
        path = two_link(Path(folder), kind2=kind2)
        text = path.read_text().replace(f'joint name="{joint_name}"', f'joint name="{link_name}"')
        path.write_text(text)
        planning = tuple(j if j != joint_name else link_name for j in ("j1", "j2"))
        planning = planning if kind2 == "revolute" else planning[:1]
        with pytest.raises(InputError, match=f"joint '{link_name}' and link '{link_name}'"):
            if loader == "planar":
                robot_from_urdf("clash", RobotSpec(urdf=path, planning_joints=planning))
            else:
                robot3d_from_urdf(path, joints=list(planning))


def _dense_surface(kind: str, r: float, length: float, n: int = 400) -> np.ndarray:
    """Dense points on a sphere, cylinder or capsule surface (its frame, axis z), (k, 3)."""
    rng = np.random.default_rng(0)
    u = rng.normal(size=(n, 3))
    ball = r * u / np.linalg.norm(u, axis=1)[:, None]
    a = np.linspace(0.0, 2 * np.pi, n, endpoint=False)
    ring = np.c_[r * np.cos(a), r * np.sin(a), np.zeros(n)]
    if kind == "sphere":
        return ball
    ends = [ring + np.array([0.0, 0.0, z]) for z in (-length / 2, length / 2)]
    if kind == "capsule":
        ends += [ball + np.array([0.0, 0.0, z]) for z in (-length / 2, length / 2)]
    return np.concatenate(ends)


@settings(max_examples=30, deadline=None)
@given(
    st.sampled_from(["sphere", "cylinder"]),
    st.lists(st.floats(-3.1, 3.1), min_size=3, max_size=3),
    st.floats(0.01, 0.3),
    st.floats(0.01, 0.5),
    st.integers(3, 16),
)
def test_a_link_polygon_contains_its_geometrys_projection(kind, rpy, r, length, most):
    """Round URDF shapes at any orientation project inside their link polygon (a polygon
    inscribed in the projection lost up to 15 % of a tilted sphere's radius: an obstacle in
    that sliver was certified clear of the link)."""
    size = f'radius="{r!r}"' if kind == "sphere" else f'radius="{r!r}" length="{length!r}"'
    rpy_text = " ".join(repr(x) for x in rpy)
    collision = (
        f'<collision><origin xyz="0.5 0 0" rpy="{rpy_text}"/>'
        f"<geometry><{kind} {size}/></geometry></collision>"
    )
    with tempfile.TemporaryDirectory() as folder:
        path = write_urdf(
            Path(folder), '<link name="base"/>', joint("j1", "base", "l1"),
            f'<link name="l1">{collision}</link>',
        )  # fmt: skip
        robot = robot_from_urdf("round_arm", RobotSpec(urdf=path, planning_joints=("j1",),
                                                       max_vertices=most))  # fmt: skip
    rotation = pin.rpy.rpyToMatrix(*rpy)
    points = _dense_surface(kind, r, length) @ rotation.T + [0.5, 0.0, 0.0]
    poly = robot.polygons[0].vertices0
    edge = np.roll(poly, -1, 0) - poly
    normal = np.c_[edge[:, 1], -edge[:, 0]] / np.linalg.norm(edge, axis=1)[:, None]
    beyond = points[:, :2] @ normal.T - np.sum(poly * normal, axis=1)  # > 0: past an edge
    assert np.max(beyond) <= 1e-9


@pytest.mark.parametrize("kind", ["sphere", "cylinder", "capsule"])
def test_geometry_points_span_a_hull_containing_the_shape(kind):
    """geometry_points of round coal shapes: their 3-D hull contains the whole surface, so
    every projection of it (any plane, any orientation) contains the shape's."""
    import coal
    from scipy.spatial import ConvexHull

    from gdnplan.urdf_robot import geometry_points

    r, length = 0.07, 0.3
    shape = {"sphere": coal.Sphere(r), "cylinder": coal.Cylinder(r, length),
             "capsule": coal.Capsule(r, length)}[kind]  # fmt: skip
    faces = ConvexHull(geometry_points(shape)).equations  # n · x + c ≤ 0 inside
    surface = _dense_surface(kind, r, length, n=2000)
    assert np.max(surface @ faces[:, :3].T + faces[:, 3]) <= 1e-12


_LIMITS_URDF = (
    Path(__file__).resolve().parent.parent / "gdnplan" / "shipped" / "robots" / "planar2.urdf"
)


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"limits": (np.zeros(3), np.ones(3))}, r"^joint limits lower: expected shape \(B, 2\)"),
        ({"limits": (np.ones(2), np.zeros(2))}, r"^joint limits: joint 0 has lower 1 ≥ upper 0"),
        ({"limits": (np.full(2, np.nan), np.ones(2))}, r"^joint limits lower: contains NaN"),
        ({"limits": (np.full(2, -1 + 1j), np.ones(2))}, r"^joint limits lower: expected real"),
        ({"limits": "x"}, r"^limits: expected \(lower, upper\) joint limits, got 'x'"),
        ({"spec": {"urdf": "x"}}, r"^spec: expected a gdnplan.RobotSpec, got dict"),
        ({"extra_polygons": "abc"}, r"^extra_polygons: expected a list of \(name, frame"),
        ({"skip_geometry": 3}, r"^skip_geometry: expected a function"),
        ({"info": [1]}, r"^info: expected a dict or None, got \[1\]"),
    ],
    ids=["3 limits", "reversed", "NaN", "complex", "str", "spec dict", "extras", "skip", "info"],
)
def test_hostile_robot_from_urdf_arguments_are_input_errors(kwargs, message):
    """Limits of another joint count, reversed, NaN or complex were accepted (the robot then
    planned with them); the others raised TypeError, ValueError or AttributeError."""
    spec = kwargs.pop("spec", gp.RobotSpec(urdf=_LIMITS_URDF, planning_joints=("joint1", "joint2")))
    with pytest.raises(gp.InputError, match=message):
        gp.robot_from_urdf("arm", spec, **kwargs)
