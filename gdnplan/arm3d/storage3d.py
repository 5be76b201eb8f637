"""The 3-D fetch storage: a table, a box with an entrance on it, the stick inside, and its poses.

The planar fetch (:mod:`gdnplan.ur5e.layout`) lifted to 3-D. World frame: the UR5e's
``base_link`` (z up, the table top at z = 0, the arm's mounting surface). The storage has its
own frame S: origin at the centre of its front face on the table, x_S into the box (away from
the robot), y_S across, z up; it is placed at (x, y, yaw) on the table (:class:`Placement`).
In S (m): the storage spans x ∈ [0, depth], |y| ≤ width/2, z ∈ [0, top]; a riser fills
z ∈ [0, floor]; walls and roof are ``wall`` thick; the front wall has a rectangular entrance
|y| ≤ entrance_width/2, z ∈ [entrance_low, entrance_high]. The stick (square section
``stick_width``, ``stick_length`` long along x_S, centred at y = 0) lies on a shelf block that
rises from the floor to z = ``shelf``; its near end, ``inset`` behind the front wall, overhangs
the block by ``overhang`` so the fingers around it stay clear of the block.

Tool poses (the UR5e's ``gripper_tcp``, :mod:`gdnplan.arm3d.ik3d`): the tool axis z along x_S
(into the box), the fingers opening across (y_tool = ±y_S), the tcp on the stick's axis:

* grasp: the palm ``GRASP_GAP`` before the stick's near end (tcp at x = stick_start + 0.005);
* pregrasp: the same attitude drawn back until the fingertips are 0.03 m before the box;
* lift: the grasp raised by ``LIFT`` = 0.02 m (the stick off its shelf);
* out: the lifted grasp drawn back until the stick's far end is 0.05 m before the box;
* home: 0.15 m before the front and 0.2 m above the box (as the planar fetch's home).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from ..limits import is_number
from ..ur5e.gripper import BODY_DEPTH, BODY_LENGTH, BODY_WIDTH, FINGER_LENGTH, GRASP_GAP, TCP
from ..ur5e.layout import LIFT
from .scene3d import Obstacle3D, box_obstacle

TABLE = ((0.15, 1.1), (-0.8, 0.8), 0.05)  # x range, y range, thickness (m): clear of the base
STICK_LENGTH = (0.15, 0.30)  # m: range of random_storage's stick length
STICK_WIDTH = (0.02, 0.04)  # m: range of random_storage's stick width
PLACEMENT_RADIUS = (0.55, 0.75)  # m: distance of the front-face centre from the base axis
PLACEMENT_BEARING = np.pi / 4  # rad: |bearing| of the front-face centre from the x axis
PLACEMENT_YAW = np.pi / 9  # rad: |yaw − bearing|, the entrance turned at most this from the base


@dataclass(frozen=True)
class Placement:
    """Where the storage stands: its front-face centre (x, y) on the table (m) and its yaw
    (rad, the direction of x_S from the world x axis)."""

    x: float
    y: float
    yaw: float

    def transform(self) -> np.ndarray:
        """(4, 4) world placement of the storage frame S."""
        c, s = np.cos(self.yaw), np.sin(self.yaw)
        out = np.eye(4)
        out[:2, :2] = [[c, -s], [s, c]]
        out[:2, 3] = self.x, self.y
        return out


@dataclass(frozen=True)
class Storage3D:
    """Sizes of the storage and the stick in the storage frame S (m); see the module doc."""

    depth: float
    width: float
    top: float
    wall: float
    floor: float
    entrance_width: float
    entrance_low: float
    entrance_high: float
    shelf: float
    inset: float
    overhang: float
    stick_length: float
    stick_width: float

    @property
    def stick_start(self) -> float:
        """x_S of the stick's near end."""
        return self.wall + self.inset

    @property
    def axis_height(self) -> float:
        """z of the stick's axis (the tcp's height at the grasp)."""
        return self.shelf + self.stick_width / 2

    def boxes(self) -> list[tuple[str, np.ndarray, np.ndarray]]:
        """(name, low corner, high corner) in S of every storage box (walls, riser, shelf)."""
        d, hw, t, top = self.depth, self.width / 2, self.wall, self.top
        ew, e0, e1, fl = self.entrance_width / 2, self.entrance_low, self.entrance_high, self.floor
        block = self.stick_start + self.overhang
        out = [
            ("riser", (0, -hw, 0), (d, hw, fl)),
            ("back", (d - t, -hw, fl), (d, hw, top)),
            ("left", (0, hw - t, fl), (d, hw, top)),
            ("right", (0, -hw, fl), (d, -hw + t, top)),
            ("roof", (0, -hw, top - t), (d, hw, top)),
            ("front_below", (0, -hw, fl), (t, hw, e0)),
            ("front_above", (0, -hw, e1), (t, hw, top)),
            ("front_left", (0, ew, e0), (t, hw, e1)),
            ("front_right", (0, -hw, e0), (t, -ew, e1)),
            ("shelf", (block, -hw + t, fl), (d - t, hw - t, self.shelf)),
        ]
        return [(n, np.array(lo, float), np.array(hi, float)) for n, lo, hi in out]

    def stick_box(self) -> tuple[np.ndarray, np.ndarray]:
        """(low, high) corners of the stick in S."""
        w = self.stick_width
        lo = np.array([self.stick_start, -w / 2, self.shelf])
        return lo, lo + np.array([self.stick_length, w, w])


def _posed_box(name: str, lo, hi, tf: np.ndarray) -> Obstacle3D | None:
    """A box obstacle of corners lo, hi in frame tf; None when it is empty (a zero side)."""
    size = np.asarray(hi) - np.asarray(lo)
    if np.any(size <= 1e-9):
        return None
    centre = tf[:3, :3] @ ((np.asarray(lo) + hi) / 2) + tf[:3, 3]
    return box_obstacle(size, centre, tf[:3, :3], name=name)


def table_obstacle() -> Obstacle3D:
    """The table slab under the storage, top at z = 0, clear of the robot's base."""
    (x0, x1), (y0, y1), t = TABLE
    return _posed_box("table", (x0, y0, -t), (x1, y1, 0.0), np.eye(4))


def storage_obstacles(storage: Storage3D, placement: Placement) -> list[Obstacle3D]:
    """The storage's boxes posed at ``placement`` (the stick not included)."""
    tf = placement.transform()
    boxes = [_posed_box(f"storage_{n}", lo, hi, tf) for n, lo, hi in storage.boxes()]
    return [b for b in boxes if b is not None]


def stick_obstacle(storage: Storage3D, placement: Placement) -> Obstacle3D:
    """The stick resting on its shelf, as an obstacle (before the grasp)."""
    lo, hi = storage.stick_box()
    box = _posed_box("stick", lo, hi, placement.transform())
    assert box is not None
    return box


def on_table(storage: Storage3D, placement: Placement) -> bool:
    """True when the storage's footprint lies on the table."""
    (x0, x1), (y0, y1), _ = TABLE
    hw = storage.width / 2
    corners = np.array([[0, -hw, 0, 1], [0, hw, 0, 1], [storage.depth, -hw, 0, 1]])
    corners = np.vstack([corners, [storage.depth, hw, 0, 1]])
    xy = (placement.transform() @ corners.T)[:2]
    return bool(np.all((xy[0] >= x0) & (xy[0] <= x1) & (xy[1] >= y0) & (xy[1] <= y1)))


# ---------------------------------------------------------------- tool poses
def tool_poses(storage: Storage3D, placement: Placement) -> dict[str, np.ndarray]:
    """World tcp positions (3,) of the fetch: grasp, pregrasp, lift, out, home (module doc)."""
    tcp_x = storage.stick_start - GRASP_GAP - BODY_LENGTH + TCP
    h = storage.axis_height
    local = {
        "grasp": (tcp_x, h),
        "pregrasp": (-0.03 - FINGER_LENGTH / 2, h),
        "lift": (tcp_x, h + LIFT),
        "out": (-0.05 - storage.stick_length - (GRASP_GAP - FINGER_LENGTH / 2), h + LIFT),
        "home": (-0.15, storage.top + 0.2),
    }
    tf = placement.transform()
    return {k: tf[:3, :3] @ np.array([x, 0.0, z]) + tf[:3, 3] for k, (x, z) in local.items()}


def tool_rotations(placement: Placement) -> list[np.ndarray]:
    """The two tool rotations (3, 3) of the fetch: z_tool = x_S, y_tool = ±y_S (the gripper is
    symmetric under a half turn about its axis, so both grasp the stick alike)."""
    rot = placement.transform()[:3, :3]
    xs, ys, zs = rot.T
    return [np.column_stack([-zs, ys, xs]), np.column_stack([zs, -ys, xs])]


# ---------------------------------------------------------------- sizes
def random_storage(rng: np.random.Generator) -> Storage3D:
    """A random storage and stick, the planar fetch's ranges (:func:`random_fetch_layout`)
    lifted to 3-D: the entrance clears the gripper body (BODY_WIDTH × BODY_DEPTH across the
    tool axis) by 0.03–0.05 m on each side, and the lift above it."""
    wall, inset, overhang = 0.02, rng.uniform(0.02, 0.06), 0.07
    length, width = rng.uniform(*STICK_LENGTH), rng.uniform(*STICK_WIDTH)
    floor = wall + rng.uniform(0.0, 0.25)
    shelf = floor + rng.uniform(0.07, 0.12)
    axis = shelf + width / 2
    side = rng.uniform(0.03, 0.05, size=3)  # clearance: across, below, above
    low = max(axis - BODY_DEPTH / 2 - side[1], floor + 0.01)
    high = axis + BODY_DEPTH / 2 + LIFT + side[2]
    entrance_width = BODY_WIDTH + 2 * side[0]
    return Storage3D(
        depth=2 * wall + inset + length + rng.uniform(0.02, 0.08),
        width=entrance_width + 2 * wall + rng.uniform(0.05, 0.15),
        top=high + wall + rng.uniform(0.05, 0.15),
        wall=wall,
        floor=floor,
        entrance_width=entrance_width,
        entrance_low=low,
        entrance_high=high,
        shelf=shelf,
        inset=inset,
        overhang=overhang,
        stick_length=length,
        stick_width=width,
    )


def random_placement(rng: np.random.Generator) -> Placement:
    """A placement within the UR5e's reach: the front-face centre at a distance in
    PLACEMENT_RADIUS and a bearing within ±PLACEMENT_BEARING, the entrance facing the base
    within ±PLACEMENT_YAW."""
    r = rng.uniform(*PLACEMENT_RADIUS)
    bearing = rng.uniform(-PLACEMENT_BEARING, PLACEMENT_BEARING)
    yaw = bearing + rng.uniform(-PLACEMENT_YAW, PLACEMENT_YAW)
    return Placement(r * np.cos(bearing), r * np.sin(bearing), yaw)


def check_placement(x, y, yaw) -> Placement:
    """A placement from user numbers: finite x, y (m) and yaw (rad), the yaw wrapped into
    [−π, π] (exactly: ``math.remainder``; sin/cos of 1e10 rad lose six digits); InputError
    otherwise."""
    if not all(is_number(v) and np.isfinite(v) for v in (x, y, yaw)):
        shown = [v.item() if isinstance(v, np.generic) else v for v in (x, y, yaw)]
        raise InputError(f"placement: expected finite x, y (m) and yaw (rad), got {shown}")
    values = [float(x), float(y), math.remainder(float(yaw), 2 * math.pi)]
    if np.hypot(values[0], values[1]) > 2.0:
        raise InputError(f"placement: ({x}, {y}) m is farther than 2 m from the robot")
    return Placement(*values)


__all__ = [
    "Placement",
    "Storage3D",
    "check_placement",
    "on_table",
    "random_placement",
    "random_storage",
    "stick_obstacle",
    "storage_obstacles",
    "table_obstacle",
    "tool_poses",
    "tool_rotations",
]
