"""How a URDF becomes a planar robot: :class:`RobotSpec`."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

from ..errors import InputError


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

    def __post_init__(self) -> None:
        names = check_names(self.planning_joints, "planning_joints", "joint names")
        object.__setattr__(self, "planning_joints", names)
        object.__setattr__(self, "locked", check_locked(self.locked))
        object.__setattr__(self, "package_dirs", check_folders(self.package_dirs))


def check_names(value, field_name: str, what: str) -> tuple[str, ...]:
    """``value`` as a tuple of strings, else InputError naming ``field_name``: a bare string
    is refused (it would iterate as its characters)."""
    if isinstance(value, (str, bytes)) or not isinstance(value, (list, tuple)):
        raise InputError(f"{field_name}: expected a list of {what}, got {value!r}")
    bad = [x for x in value if not isinstance(x, str)]
    if bad:
        raise InputError(f"{field_name}: expected a list of {what}, got {bad[0]!r} in it")
    return tuple(value)


def check_locked(locked) -> dict[str, float]:
    """``locked`` as a dict {joint name: value}, else InputError (its values are checked
    against the joints' limits when the model is known)."""
    if not isinstance(locked, Mapping) or not all(isinstance(k, str) for k in locked):
        raise InputError(f"locked: expected a table {{joint name: value}}, got {locked!r}")
    return dict(locked)


def check_folders(folders) -> tuple[str, ...]:
    """``package_dirs`` as a tuple of folder strings, else InputError (a bare string would
    iterate as its characters)."""
    if isinstance(folders, (str, bytes, Path)) or not isinstance(folders, (list, tuple)):
        raise InputError(f"package_dirs: expected a list of folders, got {folders!r}")
    bad = [d for d in folders if not isinstance(d, (str, Path))]
    if bad:
        raise InputError(f"package_dirs: expected a list of folders, got {bad[0]!r} in it")
    return tuple(str(d) for d in folders)
