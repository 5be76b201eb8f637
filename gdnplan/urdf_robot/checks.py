"""Checks of a :class:`~gdnplan.urdf_robot.spec.RobotSpec` against its model: the plane axes,
the planning joints (revolute, one serial chain, turning about the plane normal at q = 0) and
the locked joints' values, each failure an InputError or UnknownNameError naming the field."""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from ..errors import InputError, UnknownNameError
from ..limits import is_number
from ..robot_plane import Plane, joint_axis
from .locking import CONTINUOUS, lock_mimics, set_locked
from .spec import RobotSpec

AXIS_TOLERANCE = 1e-6  # largest sin(angle) between a planning joint's axis and the plane normal
PLANE_TOLERANCE = 1e-3  # largest |cos(angle)| between the given plane axes u and v
REVOLUTE = {"JointModelRX", "JointModelRY", "JointModelRZ", "JointModelRevoluteUnaligned"}
JOINT_KINDS = {"P": "prismatic", "RUB": "continuous", "FreeFlyer": "floating", "Planar": "planar"}


def plane_basis(axes) -> np.ndarray:
    """(2, 3) orthonormal rows (û, v̂) from nearly perpendicular plane axes (u, v).

    û = u/|u|, v̂ = (v − (v·û)û)/|…| (Gram–Schmidt, u kept); InputError when the axes are not
    two finite nonzero 3-vectors or |u·v|/(|u||v|) > ``PLANE_TOLERANCE``.
    """
    items = np.asarray(axes, dtype=object)
    if items.shape != (2, 3) or not all(is_number(x) for x in items.ravel()):
        raise InputError(f"plane: expected two 3-vectors [[ux, uy, uz], [vx, vy, vz]], got {axes}")
    u, v = np.asarray(axes, dtype=float)
    if not np.all(np.isfinite([u, v])) or min(np.max(np.abs(u)), np.max(np.abs(v))) < 1e-9:
        raise InputError(f"plane: the axes {axes} must be finite, nonzero directions")
    u, v = u / np.max(np.abs(u)), v / np.max(np.abs(v))  # no overflow in the norms
    u, v = u / np.linalg.norm(u), v / np.linalg.norm(v)
    if abs(u @ v) > PLANE_TOLERANCE:
        raise InputError(
            f"plane: the axes u, v are not perpendicular (u·v = {u @ v:.3g} for unit axes, "
            f"at most {PLANE_TOLERANCE}); give two perpendicular directions"
        )
    v = v - (v @ u) * u
    return np.stack([u, v / np.linalg.norm(v)])


def _check_options(spec: RobotSpec) -> None:
    """InputError for a bad ``max_vertices`` or ``base_radius``."""
    m = spec.max_vertices
    if isinstance(m, bool) or not isinstance(m, (int, np.integer)) or not 3 <= m <= 1000:
        raise InputError(f"max_vertices: expected an integer in [3, 1000], got {m!r}")
    r = spec.base_radius
    if not is_number(r) or not np.isfinite(r) or r < 0:
        raise InputError(f"base_radius: expected a finite number ≥ 0 (m), got {r!r}")


def _kind(model: pin.Model, j: int) -> str:
    """URDF-style kind of joint j ("prismatic", "continuous", …) from Pinocchio's type."""
    short = model.joints[j].shortname().removeprefix("JointModel")
    for prefix, kind in JOINT_KINDS.items():
        if short.startswith(prefix):
            return kind
    return "revolute" if model.joints[j].shortname() in REVOLUTE else short


def _reference_configuration(model: pin.Model, spec: RobotSpec, source: str) -> np.ndarray:
    """Neutral q of the full model with the locked values set; checks every joint name."""
    joints = list(model.names)[1:]
    planning = spec.planning_joints
    if not isinstance(planning, (tuple, list)) or not planning:
        raise InputError(f"joints: expected the planning joints' names, got {planning!r}")
    for jname in planning:
        if not isinstance(jname, str) or not model.existJointName(jname):
            raise UnknownNameError(
                f"joints: planning joint {jname!r} is not in {source}; its joints: {joints}"
            )
        kind = _kind(model, model.getJointId(jname))
        if kind not in ("revolute", "continuous"):
            raise InputError(
                f"joints: planning joint {jname!r} is {kind}; planning joints must be revolute "
                "(lock it with a value instead)"
            )
    if len(set(planning)) != len(planning):
        raise InputError(f"joints: {list(planning)} lists a joint twice")
    q_ref = pin.neutral(model)
    for jname, value in spec.locked.items():
        if not isinstance(jname, str) or not model.existJointName(jname):
            raise UnknownNameError(
                f"locked: joint {jname!r} is not in {source}; its joints: {joints}"
            )
        if jname in planning:
            raise InputError(f"locked: joint {jname!r} is a planning joint; lock it or plan it")
        set_locked(model, q_ref, jname, value)
    lock_mimics(model, q_ref, spec.urdf, set(spec.locked))
    return q_ref


def _check_chain(reduced: pin.Model, spec: RobotSpec) -> None:
    """InputError unless the planning joints form one serial chain listed base to tip."""
    names = list(reduced.names)[1:]
    for j in range(1, reduced.njoints):
        if reduced.parents[j] != j - 1:
            raise InputError(
                f"joints: planning joint {names[j - 1]!r} does not hang from "
                f"{names[j - 2]!r}; planning joints must form one serial chain, base to tip"
            )
        if reduced.joints[j].shortname() in CONTINUOUS:
            raise InputError(
                f"joints: planning joint {names[j - 1]!r} is continuous; load the URDF with "
                "load_urdf, which plans continuous joints within [−π, π]"
            )
    if names != list(spec.planning_joints):
        raise InputError(f"joints: list the planning joints base to tip: {names}")


def _check_axes(reduced: pin.Model, data: pin.Data, plane: Plane) -> None:
    """InputError naming the first planning joint whose axis at q = 0 is not ±n: it would move
    the robot out of the plane (or, along the plane, move nothing in plane coordinates)."""
    n = plane.normal
    for j in range(1, reduced.njoints):
        axis = data.oMi[j].rotation @ joint_axis(reduced, j)
        tilt = float(np.linalg.norm(np.cross(axis, n)))
        if tilt > AXIS_TOLERANCE:
            u, v = (np.round(a, 4).tolist() for a in plane.axes)
            raise InputError(
                f"joints: planning joint {reduced.names[j]!r} turns about the world axis "
                f"{np.round(axis, 4).tolist()} at q = 0, not about the normal of the plane "
                f"u = {u}, v = {v} (sin of the angle {tilt:.3g} > {AXIS_TOLERANCE}); choose "
                "plane axes perpendicular to the joint axes or lock the joint"
            )
