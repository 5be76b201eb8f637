"""UR5e and UR5 arms in their vertical plane, a 2F-85-like gripper, and the fetch scene.

UR5e kinematics (standard Denavit–Hartenberg, Universal Robots' published parameters)::

    T_0^6(θ) = Π_i Rz(θ_i) Tz(d_i) Tx(a_i) Rx(α_i)
    d = (0.1625, 0, 0, 0.1333, 0.0997, 0.0996) m,  a = (0, −0.425, −0.3922, 0, 0, 0) m,
    α = (π/2, 0, 0, π/2, −π/2, 0)

``robots/ur5e.urdf`` is written by :func:`ur5e_urdf` (``python robots/make_ur5e_urdf.py``): link
``i`` carries the frame F_{i−1}·Rz(θ_i), so joint ``i + 1`` sits at the constant transform
Tz(d_i) Tx(a_i) Rx(α_i) from it and Pinocchio's forward kinematics equal the DH product exactly.
The root ``base_link`` is the ROS base frame: the DH base frame ``base`` is turned by π about z,
as in Universal Robots' own description, so the arm at θ = 0 stretches along +x.

Planning plane (both arms): the vertical plane of shoulder_lift, elbow and wrist_1 at
shoulder_pan = 0, i.e. world x–z with u = x (horizontal, forward), v = z (up) and its origin at
the shoulder_lift axis (v = 0 is shoulder height, the mounting surface is at v = −d1).
wrist_2 = π/2 puts the tool axis into the plane (at q = 0 the gripper continues the stretched
arm along +u, its axis d5 = 0.0997 m below the forearm's line) and wrist_3 = 0 turns the
finger-opening direction into the plane, so the fingers open and close in the plane.
Planning joints q = (shoulder_lift, elbow, wrist_1) with limits shoulder_lift ∈ [−π, 0]
(upper arm above the shoulder's horizontal), elbow ∈ [−0.9π, 0.9π] (keeps the forearm off the
upper arm: self-collision is not modelled) and wrist_1 ∈ [−π, π]. In the plane, a positive
joint angle turns clockwise (the joint axes point along +y = −(u × v)).

Gripper (2F-85-like, attached to the tool flange): a 0.08 m long body (0.105 m across the
opening direction), two 0.05 m fingers, 0.01 m thick, on prismatic joints; the opening between
the finger faces is 0.085 m ``open``, 0 ``closed``, and the stick width when ``holding``.
The held stick is a box (``stick_width`` square section, ``stick_length`` long) along the
gripper axis, centred between the fingers, its near end ``GRASP_GAP`` in front of the palm:
it becomes one more robot polygon. Along the axis (not across it) is what a fetch through a
small entrance needs: the stick passes the entrance end first, and the fingers opening in the
plane straddle it from above and below.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import numpy as np
import pinocchio as pin

from .assets import robot_urdf
from .distance import signed_distance
from .errors import InfeasibleProblemError, InputError, UnknownNameError
from .files import atomic_path
from .limits import check_int, is_number
from .robot import Robot, load_robot, register_robot
from .scene import Scene, register_scene
from .urdf_robot import RobotSpec, robot_from_models

PI = float(np.pi)


@dataclass(frozen=True)
class DH:
    """Standard DH parameters of a six-axis arm (m, rad), one entry per joint."""

    d: tuple[float, ...]
    a: tuple[float, ...]
    alpha: tuple[float, ...]

    def forward(self, q: np.ndarray) -> np.ndarray:
        """Flange poses T_0^6 (B, 4, 4) in the DH base frame for joint angles q (B, 6).

        T_{i−1}^i = Rz(θ_i) Tz(d_i) Tx(a_i) Rx(α_i), written out as the textbook matrix.
        """
        q = np.atleast_2d(np.asarray(q, dtype=float))
        out = np.broadcast_to(np.eye(4), (len(q), 4, 4)).copy()
        for i in range(6):
            ct, st = np.cos(q[:, i]), np.sin(q[:, i])
            ca, sa = np.cos(self.alpha[i]), np.sin(self.alpha[i])
            t = np.zeros((len(q), 4, 4))
            t[:, 0] = np.stack([ct, -st * ca, st * sa, self.a[i] * ct], 1)
            t[:, 1] = np.stack([st, ct * ca, -ct * sa, self.a[i] * st], 1)
            t[:, 2] = [0.0, sa, ca, self.d[i]]
            t[:, 3] = [0.0, 0.0, 0.0, 1.0]
            out = out @ t
        return out


UR5E_DH = DH(
    d=(0.1625, 0.0, 0.0, 0.1333, 0.0997, 0.0996),
    a=(0.0, -0.425, -0.3922, 0.0, 0.0, 0.0),
    alpha=(PI / 2, 0.0, 0.0, PI / 2, -PI / 2, 0.0),
)
UR5_DH = DH(  # the classic UR5 (example-robot-data's ur5)
    d=(0.089159, 0.0, 0.0, 0.10915, 0.09465, 0.0823),
    a=(0.0, -0.425, -0.39225, 0.0, 0.0, 0.0),
    alpha=(PI / 2, 0.0, 0.0, PI / 2, -PI / 2, 0.0),
)
JOINTS = (
    "shoulder_pan_joint",
    "shoulder_lift_joint",
    "elbow_joint",
    "wrist_1_joint",
    "wrist_2_joint",
    "wrist_3_joint",
)
LINKS = (
    "shoulder_link",
    "upper_arm_link",
    "forearm_link",
    "wrist_1_link",
    "wrist_2_link",
    "wrist_3_link",
)
PLANNING_JOINTS = JOINTS[1:4]
LOCKED = {"shoulder_pan_joint": 0.0, "wrist_2_joint": PI / 2, "wrist_3_joint": 0.0}
PLANNING_LIMITS = (np.array([-PI, -0.9 * PI, -PI]), np.array([0.0, 0.9 * PI, PI]))
PLANE_AXES = ((1.0, 0.0, 0.0), (0.0, 0.0, 1.0))

# gripper (m), in the gripper frame: z along the tool axis, y the opening direction
BODY_LENGTH, BODY_WIDTH, BODY_DEPTH = 0.08, 0.105, 0.07
FINGER_LENGTH, FINGER_THICKNESS, FINGER_DEPTH = 0.05, 0.01, 0.022
MAX_OPENING = 0.085
GRASP_GAP = 0.02  # stick end to palm (m)
TCP = BODY_LENGTH + FINGER_LENGTH / 2  # grasp centre on the tool axis, from the flange
GRIPPER_STATES = ("open", "closed", "holding")
MAX_FETCH_TRIES = 1000  # fetch_scene: random layouts drawn at most
POLYGON_GROUPS = {  # URDF link -> robot polygon (hull of the link's projected geometry)
    "base_link": "base",
    "shoulder_link": "base",
    "upper_arm_link": "upper_arm",
    "forearm_link": "forearm",
    "wrist_1_link": "wrist",
    "wrist_2_link": "hand",
    "wrist_3_link": "hand",
    "gripper_base_link": "hand",
    "left_finger_link": "finger_left",
    "right_finger_link": "finger_right",
    "stick": "stick",
}


# -------------------------------------------------------------------- URDF
def _cylinder(radius: float, length: float, xyz, axis: str) -> str:
    rpy = {"x": (0, PI / 2, 0), "y": (PI / 2, 0, 0), "z": (0, 0, 0)}[axis]
    return _collision(f'<cylinder radius="{radius!r}" length="{length!r}"/>', xyz, rpy)


def _box(size, xyz) -> str:
    return _collision(f'<box size="{" ".join(repr(float(s)) for s in size)}"/>', xyz, (0, 0, 0))


def _collision(shape: str, xyz, rpy) -> str:
    return (
        f'    <collision><origin xyz="{_v(xyz)}" rpy="{_v(rpy)}"/>'
        f"<geometry>{shape}</geometry></collision>"
    )


def _v(x) -> str:
    return " ".join(repr(float(c)) for c in x)


def _link(name: str, *collisions: str) -> str:
    return "\n".join([f'  <link name="{name}">', *collisions, "  </link>"])


def _joint(name, kind, parent, child, xyz=(0, 0, 0), rpy=(0, 0, 0), axis=None, limit=None) -> str:
    lines = [
        f'  <joint name="{name}" type="{kind}">',
        f'    <parent link="{parent}"/><child link="{child}"/>',
        f'    <origin xyz="{_v(xyz)}" rpy="{_v(rpy)}"/>',
    ]
    if axis is not None:
        lines.append(f'    <axis xyz="{_v(axis)}"/>')
    if limit is not None:
        lines.append(
            f'    <limit lower="{limit[0]!r}" upper="{limit[1]!r}" effort="{limit[2]!r}" '
            f'velocity="{limit[3]!r}"/>'
        )
    return "\n".join([*lines, "  </joint>"])


def ur5e_urdf() -> str:
    """The UR5e + gripper URDF (the text of ``robots/ur5e.urdf``).

    Collision geometry from the datasheet: base Ø 0.149 m, shoulder Ø 0.12, elbow Ø 0.10,
    upper-arm tube Ø 0.09, forearm tube Ø 0.075, wrist housings Ø 0.09. Out-of-plane offsets
    (shoulder 0.138 m, forearm 0.007 m, wrist d4) follow the real arm; they vanish in the plane.
    """
    d, a, alpha = UR5E_DH.d, UR5E_DH.a, UR5E_DH.alpha
    limits = [(-2 * PI, 2 * PI, 150.0, PI)] * 2 + [(-PI, PI, 150.0, PI)]
    limits += [(-2 * PI, 2 * PI, 28.0, PI)] * 3
    geometry = {
        "shoulder_link": [
            _cylinder(0.06, d[0] - 0.086, (0, 0, (0.086 + d[0]) / 2), "z"),
            _cylinder(0.06, 0.14, (0, -0.07, d[0]), "y"),
        ],
        "upper_arm_link": [
            _cylinder(0.06, 0.12, (0, 0, 0.12), "z"),
            _cylinder(0.045, -a[1], (a[1] / 2, 0, 0.138), "x"),
            _cylinder(0.05, 0.11, (a[1], 0, 0.07), "z"),
        ],
        "forearm_link": [
            _cylinder(0.05, 0.10, (0, 0, 0.04), "z"),
            _cylinder(0.0375, -a[2], (a[2] / 2, 0, 0.007), "x"),
            _cylinder(0.045, 0.10, (a[2], 0, 0.06), "z"),
        ],
        "wrist_1_link": [
            _cylinder(0.045, 0.10, (0, 0, d[3] - 0.05), "z"),
            _cylinder(0.045, d[4] + 0.045, (0, -(d[4] + 0.045) / 2, d[3]), "y"),
        ],
        "wrist_2_link": [_cylinder(0.045, d[5] + 0.045, (0, (d[5] - 0.045) / 2, d[4]), "y")],
        "wrist_3_link": [_cylinder(0.032, 0.015, (0, 0, d[5] - 0.0075), "z")],
    }
    parts = [
        '<?xml version="1.0"?>',
        "<!-- generated by robots/make_ur5e_urdf.py from gdnplan.ur5e.ur5e_urdf; do not edit -->",
        '<robot name="ur5e">',
        _link("base_link", _cylinder(0.0745, 0.086, (0, 0, 0.043), "z")),
        _joint("base_link-base_fixed_joint", "fixed", "base_link", "base", rpy=(0, 0, PI)),
        '  <link name="base"/>',
    ]
    parent = "base"
    for i, (joint, link) in enumerate(zip(JOINTS, LINKS, strict=True)):
        xyz, rpy = (
            ((0, 0, 0), (0, 0, 0)) if i == 0 else ((a[i - 1], 0, d[i - 1]), (alpha[i - 1], 0, 0))
        )
        parts.append(_joint(joint, "revolute", parent, link, xyz, rpy, (0, 0, 1), limits[i]))
        parts.append(_link(link, *geometry[link]))
        parent = link
    parts += [
        _joint(
            "wrist_3-flange", "fixed", "wrist_3_link", "flange", (a[5], 0, d[5]), (alpha[5], 0, 0)
        ),
        '  <link name="flange"/>',
        _joint("flange-gripper", "fixed", "flange", "gripper_base_link"),
        _link(
            "gripper_base_link",
            _box((BODY_DEPTH, BODY_WIDTH, BODY_LENGTH), (0, 0, BODY_LENGTH / 2)),
        ),
    ]
    finger = (FINGER_DEPTH, FINGER_THICKNESS, FINGER_LENGTH)
    for side, sign in (("left", 1.0), ("right", -1.0)):
        parts += [
            _joint(
                f"{side}_finger_joint",
                "prismatic",
                "gripper_base_link",
                f"{side}_finger_link",
                (0, 0, BODY_LENGTH),
                axis=(0, sign, 0),
                limit=(0.0, MAX_OPENING / 2, 20.0, 0.15),
            ),
            _link(
                f"{side}_finger_link",
                _box(finger, (0, sign * FINGER_THICKNESS / 2, FINGER_LENGTH / 2)),
            ),
        ]
    parts += [
        _joint("gripper-tcp", "fixed", "gripper_base_link", "gripper_tcp", (0, 0, TCP)),
        '  <link name="gripper_tcp"/>',
        "</robot>",
        "",
    ]
    return "\n".join(parts)


# -------------------------------------------------------------------- robots
def _group(geometry_name: str) -> str:
    """Polygon of a Pinocchio geometry name ``<link>_<index>``."""
    return POLYGON_GROUPS[geometry_name.rsplit("_", 1)[0]]


def _add_stick(model: pin.Model, geom: pin.GeometryModel, length: float, width: float) -> None:
    """Attach the held stick (a box along the tool axis) to the gripper body."""
    import coal

    frame = model.getFrameId("gripper_base_link")
    local = pin.SE3(np.eye(3), np.array([0.0, 0.0, BODY_LENGTH + GRASP_GAP + length / 2]))
    placement = model.frames[frame].placement * local  # geometry placements are joint-relative
    box = coal.Box(width, width, length)
    geom.addGeometryObject(
        pin.GeometryObject("stick_0", model.frames[frame].parentJoint, frame, placement, box)
    )


@lru_cache(maxsize=32)
def _ur5e(gripper: str, stick_length: float, stick_width: float) -> Robot:
    urdf = robot_urdf("ur5e")
    model = pin.buildModelFromUrdf(str(urdf))
    geom = pin.buildGeomFromUrdf(model, str(urdf), pin.GeometryType.COLLISION)
    half = {"open": MAX_OPENING / 2, "closed": 0.0, "holding": stick_width / 2}[gripper]
    if gripper == "holding":
        _add_stick(model, geom, stick_length, stick_width)
    spec = RobotSpec(
        urdf=urdf,
        planning_joints=PLANNING_JOINTS,
        locked={**LOCKED, "left_finger_joint": half, "right_finger_joint": half},
        plane_axes=PLANE_AXES,
        max_vertices=12,
        base_radius=0.2,
    )
    info = {"gripper": gripper, "opening": 2 * half, "tcp_frame": "gripper_tcp"}
    if gripper == "holding":
        info.update(stick_length=stick_length, stick_width=stick_width)
    return robot_from_models("ur5e", model, geom, spec, PLANNING_LIMITS, info=info, group=_group)


@register_robot("ur5e")
def ur5e(gripper: str = "open", stick_length: float = 0.25, stick_width: float = 0.03) -> Robot:
    """The UR5e with its gripper ``open``, ``closed`` or ``holding`` a stick, dof = 3.

    Polygons: base (base + shoulder, fixed), upper_arm, forearm, wrist (wrist_1 link), hand
    (wrist_2/3 links + gripper body), finger_left, finger_right, and stick when holding.
    ``stick_length`` and ``stick_width`` (m) size the held stick (ignored otherwise).
    """
    if gripper not in GRIPPER_STATES:
        raise UnknownNameError(
            f"gripper: unknown state {gripper!r}; choose one of {list(GRIPPER_STATES)}"
        )
    for field_name, value, low, high in (
        ("stick_length", stick_length, 0.02, 1.0),
        ("stick_width", stick_width, 0.005, MAX_OPENING),
    ):
        if not is_number(value) or not low <= value <= high:
            raise InputError(f"{field_name}: expected a length in [{low}, {high}] m, got {value!r}")
    if gripper != "holding":  # one robot per state: the stick size only matters when held
        stick_length, stick_width = 0.25, 0.03
    return _ur5e(gripper, float(stick_length), float(stick_width))


# -------------------------------------------------------------------- planar end effector
def tcp_pose(robot: Robot, q: np.ndarray) -> np.ndarray:
    """Planar pose (u, v, φ) of the grasp centre: position (m) and tool-axis angle φ (rad)."""
    model = robot.model
    data = model.createData()
    pin.framesForwardKinematics(model, data, np.asarray(q, dtype=float))
    frame = data.oMf[model.getFrameId("gripper_tcp")]
    axis = robot.plane.axes @ frame.rotation[:, 2]
    return np.array([*robot.plane.project(frame.translation), np.arctan2(axis[1], axis[0])])


def solve_ik(robot: Robot, target: np.ndarray) -> list[np.ndarray]:
    """Exact planar inverse kinematics of the tcp pose ``target`` = (u, v, φ), both elbows.

    Body j turns by θ_j = Σ_{i≤j} s_i q_i. The tcp is rigid on body 3, so joint 3 sits at
    o₃(q) = p* − R(θ₃) c with c = tcp − o₃ at q = 0 and θ₃ = φ* − φ(0). Reaching
    w = o₃ − o₁ with links ℓ₁ = |o₂ − o₁|, ℓ₂ = |o₃ − o₂| (directions β₁, β₂ at q = 0) gives the
    elbow angle γ = ±acos((|w|² − ℓ₁² − ℓ₂²) / 2ℓ₁ℓ₂), the first link's direction
    a₁ = ∠w − atan2(ℓ₂ sin γ, ℓ₁ + ℓ₂ cos γ), θ₁ = a₁ − β₁, θ₂ = a₁ + γ − β₂. Angles are
    shifted by 2π into the joint limits; solutions outside them are dropped.

    Returns:
        0, 1 or 2 configurations (3,) (rad), each checked against Pinocchio's tcp pose.
    """
    o, s = robot.chain.joint_origins, robot.chain.joint_signs
    zero = tcp_pose(robot, np.zeros(robot.dof))
    theta3 = target[2] - zero[2]
    c3, s3 = np.cos(theta3), np.sin(theta3)
    c = zero[:2] - o[2]
    w = target[:2] - np.array([c3 * c[0] - s3 * c[1], s3 * c[0] + c3 * c[1]]) - o[0]
    l1v, l2v = o[1] - o[0], o[2] - o[1]
    l1, l2 = np.linalg.norm(l1v), np.linalg.norm(l2v)
    cos_g = (w @ w - l1**2 - l2**2) / (2 * l1 * l2)
    if abs(cos_g) > 1:
        return []
    found = []
    for gamma in {np.arccos(cos_g), -np.arccos(cos_g)}:
        a1 = np.arctan2(w[1], w[0]) - np.arctan2(l2 * np.sin(gamma), l1 + l2 * np.cos(gamma))
        theta1 = a1 - np.arctan2(l1v[1], l1v[0])
        theta2 = a1 + gamma - np.arctan2(l2v[1], l2v[0])
        q = s * np.array([theta1, theta2 - theta1, theta3 - theta2])
        q = (q + np.pi) % (2 * np.pi) - np.pi
        q = np.where(q > robot.upper, q - 2 * np.pi, np.where(q < robot.lower, q + 2 * np.pi, q))
        if robot.within_limits(q)[0]:
            pose = tcp_pose(robot, q)
            err = np.r_[pose[:2] - target[:2], np.sin(pose[2] - target[2])]
            assert np.abs(err).max() < 1e-9, f"planar IK disagrees with Pinocchio: {err}"
            found.append(q)
    return found


# -------------------------------------------------------------------- the fetch scene
TABLE_V = -UR5E_DH.d[0]  # table top in plane coordinates: the UR5e's mounting surface (m)
LIFT = 0.02  # m: after closing, the gripper lifts the stick this far off its shelf


@dataclass(frozen=True)
class FetchLayout:
    """Storage box and stick of a fetch scene, plane coordinates (m).

    The storage is a box standing on the table (outer u ∈ [front, front + depth], v from the
    table top to ``top``) with walls ``wall`` thick, an inner floor at ``floor`` (a thick
    bottom is a box on a riser), and an entrance in its front wall (the side facing the robot)
    spanning v ∈ ``entrance``. The stick lies horizontally on a shelf block that rises from the
    floor; the stick's near end, ``inset`` behind the front wall, overhangs the block by
    ``overhang`` so the lower finger can pass beneath it.
    """

    front: float
    depth: float
    top: float
    wall: float
    floor: float
    entrance: tuple[float, float]
    shelf: float  # shelf block top = stick bottom
    inset: float
    overhang: float
    stick_length: float
    stick_width: float

    @property
    def stick_start(self) -> float:
        """u of the stick's near end."""
        return self.front + self.wall + self.inset

    @property
    def stick_center(self) -> np.ndarray:
        return np.array(
            [self.stick_start + self.stick_length / 2, self.shelf + self.stick_width / 2]
        )

    def stick(self) -> np.ndarray:
        """(4, 2) stick rectangle."""
        lo = np.array([self.stick_start, self.shelf])
        hi = lo + np.array([self.stick_length, self.stick_width])
        return np.array([lo, [hi[0], lo[1]], hi, [lo[0], hi[1]]])

    def storage(self) -> np.ndarray:
        """(14, 2) CCW storage polygon: walls, bottom, shelf block, open at the entrance."""
        x0, x1, t = self.front, self.front + self.depth, self.wall
        y0, y1, (e0, e1) = TABLE_V, self.top, self.entrance
        block = self.stick_start + self.overhang
        return np.array(
            [
                [x0, y0], [x1, y0], [x1, y1], [x0, y1], [x0, e1], [x0 + t, e1],
                [x0 + t, y1 - t], [x1 - t, y1 - t], [x1 - t, self.shelf], [block, self.shelf],
                [block, self.floor], [x0 + t, self.floor], [x0 + t, e0], [x0, e0],
            ]
        )  # fmt: skip

    def table(self) -> np.ndarray:
        """(4, 2) table slab: top at the mounting surface, from in front of the base to 1.5 m."""
        return np.array(
            [[0.2, TABLE_V - 0.05], [1.5, TABLE_V - 0.05], [1.5, TABLE_V], [0.2, TABLE_V]]
        )

    def grasp_target(self) -> np.ndarray:
        """tcp pose (u, v, φ) of the grasp: gripper horizontal, palm GRASP_GAP before the stick."""
        centre = self.stick_start - GRASP_GAP - BODY_LENGTH + TCP
        return np.array([centre, self.shelf + self.stick_width / 2, 0.0])

    def pregrasp_target(self) -> np.ndarray:
        """tcp pose of the grasp drawn back until the fingertips are 0.03 m before the box."""
        fingertips = self.front - 0.03
        return np.array([fingertips - FINGER_LENGTH / 2, *self.grasp_target()[1:]])

    def lift_target(self) -> np.ndarray:
        """tcp pose of the grasp raised by LIFT: the held stick off its shelf."""
        return self.grasp_target() + np.array([0.0, LIFT, 0.0])

    def out_target(self) -> np.ndarray:
        """tcp pose with the held stick lifted out: 0.15 m before the front, 0.1 m above the box."""
        return np.array([self.front - 0.15, self.top + 0.1, 0.0])

    def home_target(self) -> np.ndarray:
        """tcp pose of the open gripper 0.15 m before the front and 0.2 m above the box."""
        return np.array([self.front - 0.15, self.top + 0.2, 0.0])


CANONICAL_FETCH = FetchLayout(
    front=0.62,
    depth=0.36,
    top=0.16,
    wall=0.02,
    floor=TABLE_V + 0.02,
    entrance=(-0.1375, 0.0425),
    shelf=-0.0625,
    inset=0.03,
    overhang=0.07,
    stick_length=0.25,
    stick_width=0.03,
)


def random_fetch_layout(rng: np.random.Generator) -> FetchLayout:
    """A random storage (placement, size, riser, entrance height and size) and stick."""
    wall, inset, overhang = 0.02, rng.uniform(0.02, 0.06), 0.07
    length, width = rng.uniform(0.15, 0.30), rng.uniform(0.02, 0.04)
    floor = TABLE_V + wall + rng.uniform(0.0, 0.25)
    shelf = floor + rng.uniform(0.07, 0.12)
    half = rng.uniform(0.09, 0.11)  # half the entrance height, around the stick's axis
    centre = shelf + width / 2
    entrance = (max(centre - half, floor + 0.01), centre + half)
    return FetchLayout(
        front=rng.uniform(0.55, 0.75),
        depth=2 * wall + inset + length + rng.uniform(0.02, 0.08),
        top=entrance[1] + wall + rng.uniform(0.05, 0.15),
        wall=wall,
        floor=floor,
        entrance=entrance,
        shelf=shelf,
        inset=inset,
        overhang=overhang,
        stick_length=length,
        stick_width=width,
    )


MIN_CLEARANCE = 0.015  # m: q_grasp, q_home and q_out keep at least this signed distance


def _fetch_scenes(layout: FetchLayout) -> dict[str, Scene]:
    """The layout's scene for each gripper state (the held stick is no obstacle)."""
    fixed = (layout.table(), layout.storage())
    held = load_robot(
        "ur5e",
        gripper="holding",
        stick_length=layout.stick_length,
        stick_width=layout.stick_width,
    )
    return {
        "open": Scene(load_robot("ur5e", gripper="open"), (*fixed, layout.stick()), "fetch"),
        "closed": Scene(load_robot("ur5e", gripper="closed"), (*fixed, layout.stick()), "fetch"),
        "holding": Scene(held, fixed, "fetch"),
    }


def _best(scene: Scene, candidates: list[np.ndarray], near: np.ndarray | None) -> np.ndarray | None:
    """The candidate with clearance ≥ MIN_CLEARANCE, closest to ``near`` (else most clear)."""
    if not candidates:
        return None
    q = np.array(candidates)
    ok = signed_distance(scene, q) >= MIN_CLEARANCE
    if not ok.any():
        return None
    q = q[ok]
    if near is None:
        return q[np.argmax(signed_distance(scene, q))]
    return q[np.argmin(np.abs(q - near).sum(1))]


def fetch_configurations(layout: FetchLayout) -> dict[str, np.ndarray] | None:
    """Free configurations of a layout (coal clearance ≥ MIN_CLEARANCE), or None.

    ``q_grasp``: gripper open and horizontal through the entrance, fingers around the stick's
    near end (the stick an obstacle). ``q_pregrasp``: the same gripper attitude drawn back out of
    the entrance (a waypoint for planners). ``q_lift``: the same grasp raised by LIFT, stick held.
    ``q_home`` (gripper open, above and in front of the box) and ``q_out`` (stick held, entirely
    outside the box) are the free IK solutions nearest to q_grasp. The fetch sequence is
    home → pregrasp → grasp (open), close, lift → out (holding).
    """
    scenes = _fetch_scenes(layout)
    robot = scenes["open"].robot
    q_grasp = _best(scenes["open"], solve_ik(robot, layout.grasp_target()), None)
    if q_grasp is None:
        return None
    configs = {"q_grasp": q_grasp}
    for key, target, state in (
        ("q_pregrasp", layout.pregrasp_target(), "open"),
        ("q_lift", layout.lift_target(), "holding"),
        ("q_home", layout.home_target(), "open"),
        ("q_out", layout.out_target(), "holding"),
    ):
        configs[key] = _best(scenes[state], solve_ik(robot, target), q_grasp)
        if configs[key] is None:
            return None
    return configs


@register_scene("fetch")
def fetch_scene(seed: int = 0, gripper: str = "open", max_tries: int = 100) -> Scene:
    """UR5e with its gripper, a table, a storage box with a small entrance and a stick inside.

    seed = 0 is the canonical layout (:data:`CANONICAL_FETCH`); other seeds draw random
    layouts (:func:`random_fetch_layout`), redrawn until :func:`fetch_configurations` finds
    free grasp, home and out configurations (at most ``max_tries`` ≤ 1 000 draws). ``gripper``
    selects the robot: ``open``/``closed`` with the stick an obstacle, or ``holding`` it (the
    stick is then part of the robot and no obstacle).

    ``info``: ``layout`` (FetchLayout), ``storage`` and ``stick`` and ``table`` polygons,
    ``entrance`` (u, v_low, v_high), ``stick_center``, ``stick_length``, ``stick_width``,
    ``grasp_tcp`` (u, v, φ), ``q_grasp``, ``q_pregrasp``, ``q_lift``, ``q_home``, ``q_out`` (3,) and
    ``gripper``.
    """
    if gripper not in GRIPPER_STATES:
        raise UnknownNameError(
            f"gripper: unknown state {gripper!r}; choose one of {list(GRIPPER_STATES)}"
        )
    check_int(max_tries, "max_tries", 1, MAX_FETCH_TRIES)
    rng = np.random.default_rng(seed)
    for _ in range(max_tries):
        layout = CANONICAL_FETCH if seed == 0 else random_fetch_layout(rng)
        configs = fetch_configurations(layout)
        if configs is not None:
            break
        if seed == 0:
            raise InfeasibleProblemError("fetch: the canonical layout has no free grasp")
    else:
        raise InfeasibleProblemError(
            f"fetch: seed {seed}: no layout with a free grasp in max_tries={max_tries} draws"
        )
    scene = _fetch_scenes(layout)[gripper]
    info = {
        "layout": layout,
        "gripper": gripper,
        "table": layout.table(),
        "storage": layout.storage(),
        "stick": layout.stick(),
        "entrance": (layout.front, *layout.entrance),
        "stick_center": layout.stick_center,
        "stick_length": layout.stick_length,
        "stick_width": layout.stick_width,
        "grasp_tcp": layout.grasp_target(),
        **configs,
    }
    return Scene(scene.robot, scene.obstacles, name="fetch", seed=seed, info=info)


def plot_fetch(scene: Scene, q: np.ndarray, path: str) -> None:
    """Save a PNG of the scene with the robot at q (3,): obstacles grey, links coloured."""
    import matplotlib.pyplot as plt
    from matplotlib.patches import Polygon as Patch

    fig, ax = plt.subplots(figsize=(8, 5.5))
    stick = scene.info.get("stick")
    for poly in scene.obstacles:
        is_stick = stick is not None and poly.shape == stick.shape and np.allclose(poly, stick)
        ax.add_patch(Patch(poly, facecolor="goldenrod" if is_stick else "0.75", edgecolor="0.3"))
    colors = ["tab:blue", "tab:orange", "tab:green", "tab:red", "tab:purple", "tab:brown"]
    colors += ["tab:pink", "tab:olive", "tab:cyan"]
    links = scene.robot.polygons
    for i, (link, poly) in enumerate(zip(links, scene.robot.link_polygons(q), strict=True)):
        ax.add_patch(Patch(poly, alpha=0.6, facecolor=colors[i % len(colors)], label=link.name))
    d = float(signed_distance(scene, q)[0])
    ax.set_title(
        f"{scene.name} seed {scene.seed}, gripper {scene.robot.info['gripper']}: "
        f"q = {np.round(q, 3).tolist()}, clearance {d * 1000:.1f} mm"
    )
    ax.set(xlim=(-0.4, 1.3), ylim=(-0.3, 0.9), aspect="equal", xlabel="u (m)", ylabel="v (m)")
    ax.legend(loc="upper right", fontsize=7)
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=110, bbox_inches="tight")
    plt.close(fig)


UR5_GROUPS = {
    "base_link": "base",
    "shoulder_link": "base",
    "upper_arm_link": "upper_arm",
    "forearm_link": "forearm",
    "wrist_1_link": "wrist",
    "wrist_2_link": "hand",
    "wrist_3_link": "hand",
    "ee_link": "hand",
}


@register_robot("ur5")
def ur5() -> Robot:
    """The classic UR5 of example-robot-data, polygons projected from its collision meshes.

    Same plane, planning joints and limits as the UR5e; wrist_2 = π/2 puts the tool axis
    in the plane (along +u at q = 0). Polygons: base, upper_arm, forearm, wrist, hand.
    """
    import example_robot_data

    loaded = example_robot_data.load("ur5")
    spec = RobotSpec(
        urdf=Path(loaded.urdf),
        planning_joints=PLANNING_JOINTS,
        locked={"shoulder_pan_joint": 0.0, "wrist_2_joint": PI / 2, "wrist_3_joint": 0.0},
        plane_axes=PLANE_AXES,
        max_vertices=12,
        base_radius=0.2,
    )
    return robot_from_models(
        "ur5",
        loaded.model,
        loaded.collision_model,
        spec,
        PLANNING_LIMITS,
        info={"source": "example-robot-data ur5"},
        group=lambda name: UR5_GROUPS[name.rsplit("_", 1)[0]],
    )
