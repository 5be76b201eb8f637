"""The parts a planar :class:`~gdnplan.robot.Robot` is made of: its planning :class:`Plane` (2-D
coordinates of world points), the convex :class:`LinkPolygon` attached to each body, rigid
transforms of points (:func:`apply_se3`) and the axes of revolute joints (:func:`joint_axis`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from .errors import InputError
from .limits import read_only


@dataclass(frozen=True)
class LinkPolygon:
    """A convex polygon rigidly attached to one body of the chain.

    Attributes:
        name: e.g. ``"link3"`` or ``"forearm_link_0"``.
        body: planning joints upstream (0 = fixed base, dof = last body).
        frame: Pinocchio frame id the polygon is attached to.
        vertices0: (m, 2) CCW vertices in plane coordinates at q = 0 (m).
        vertices_frame: (m, 3) the same points in the frame's coordinates (Pinocchio reference).
    """

    name: str
    body: int
    frame: int
    vertices0: np.ndarray
    vertices_frame: np.ndarray

    def __post_init__(self) -> None:  # read-only: the checkers and lever arms cache them
        object.__setattr__(self, "vertices0", read_only(self.vertices0))
        object.__setattr__(self, "vertices_frame", read_only(self.vertices_frame))


@dataclass(frozen=True)
class Plane:
    """The planning plane: 2-D coordinates u = axes · (x − origin) of a world point x (3,)."""

    origin: np.ndarray
    axes: np.ndarray  # (2, 3), orthonormal rows

    def __post_init__(self) -> None:
        object.__setattr__(self, "origin", read_only(self.origin))
        object.__setattr__(self, "axes", read_only(self.axes))

    @property
    def normal(self) -> np.ndarray:
        return np.cross(self.axes[0], self.axes[1])

    def project(self, x: np.ndarray) -> np.ndarray:
        """World points (..., 3) -> plane coordinates (..., 2)."""
        return (x - self.origin) @ self.axes.T

    def lift(self, u: np.ndarray) -> np.ndarray:
        """Plane coordinates (..., 2) -> world points (..., 3) on the plane."""
        return self.origin + u @ self.axes


def apply_se3(placement: pin.SE3, points: np.ndarray) -> np.ndarray:
    """Apply a rigid transform to points (k, 3)."""
    return points @ placement.rotation.T + placement.translation


def joint_axis(model: pin.Model, j: int) -> np.ndarray:
    """Unit axis of revolute joint j in its own frame."""
    shortname = model.joints[j].shortname()
    fixed = {"JointModelRX": (1, 0, 0), "JointModelRY": (0, 1, 0), "JointModelRZ": (0, 0, 1)}
    if shortname in fixed:
        return np.array(fixed[shortname], dtype=float)
    if shortname == "JointModelRevoluteUnaligned":
        return np.asarray(model.joints[j].extract().axis, dtype=float)
    raise InputError(f"joint {model.names[j]!r}: only revolute joints can be planning joints")
