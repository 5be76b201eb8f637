"""Fetch layouts: a storage box with an entrance on the UR5e's table, and the stick inside.

Plane coordinates (m) of :mod:`gdnplan.ur5e.kinematics`; the tcp targets of a layout (grasp,
pregrasp, lift, out, home) are poses (u, v, φ) of the grasp centre, as
:func:`gdnplan.ur5e.tcp_pose` gives them.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .gripper import BODY_LENGTH, FINGER_LENGTH, GRASP_GAP, TCP
from .kinematics import UR5E_DH

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
