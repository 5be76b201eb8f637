"""How a URDF becomes a planar robot: :class:`RobotSpec`."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path


@dataclass(frozen=True)
class RobotSpec:
    """How to turn a URDF into a planar :class:`~gdnplan.robot.Robot`.

    Attributes:
        urdf: path of the URDF; ``package://`` meshes resolve against ``package_dirs`` and
            the URDF's parent folders.
        planning_joints: names of the joints that move, base to tip: a serial chain of
            revolute (or continuous, planned within [−π, π]) joints turning about the plane
            normal at q = 0.
        locked: values of other joints (rad or m); unlisted non-planning joints lock at 0.
        plane_axes: (2, 3) world directions u, v of the plane coordinates; nearly
            perpendicular (|û · v̂| ≤ 1e-3), then made exactly orthonormal (u kept).
        package_dirs: folders searched for ``package://`` meshes.
        max_vertices: each link polygon is simplified to at most this many vertices (≥ 3).
        base_radius: keep-out radius around joint 1 for generated obstacles (m).
    """

    urdf: Path
    planning_joints: tuple[str, ...]
    locked: dict[str, float] = field(default_factory=dict)
    plane_axes: tuple[tuple[float, ...], tuple[float, ...]] = ((1, 0, 0), (0, 1, 0))
    package_dirs: tuple[str, ...] = ()
    max_vertices: int = 12
    base_radius: float = 0.15
