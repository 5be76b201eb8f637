"""Locked joints: their values in the full model's configuration (the reference the reduced
model is built at), shared by the planar (:mod:`gdnplan.urdf_robot.checks`) and 3-D
(:mod:`gdnplan.arm3d.robot3d`) loaders, and the ``<mimic>`` followers among them."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pinocchio as pin

from ..errors import InputError
from ..files import read_input
from ..limits import is_number

CONTINUOUS = {"JointModelRUBX", "JointModelRUBY", "JointModelRUBZ"}
LIMIT_SLACK = 1e-9  # rad or m a locked value may lie beyond its joint's limits


def outside_limits(model: pin.Model, idx_q: int, value: float) -> tuple[float, float] | None:
    """The limits (lo, hi) of coordinate ``idx_q`` when ``value`` lies outside them (beyond
    ``LIMIT_SLACK``), else None."""
    lo, hi = model.lowerPositionLimit[idx_q], model.upperPositionLimit[idx_q]
    return None if lo - LIMIT_SLACK <= value <= hi + LIMIT_SLACK else (lo, hi)


def set_locked(model: pin.Model, q: np.ndarray, jname: str, value) -> None:
    """Write joint ``jname`` locked at ``value`` into ``q`` (the full model's configuration, in
    place): a continuous joint at any angle as (cos θ, sin θ), a one-coordinate joint within
    its limits; InputError for a value that is not a finite number, outside the limits, or a
    joint of several coordinates."""
    if not is_number(value) or not np.isfinite(value):
        raise InputError(f"locked: joint {jname!r} needs a finite number, got {value!r}")
    joint = model.joints[model.getJointId(jname)]
    if joint.shortname() in CONTINUOUS:
        q[joint.idx_q : joint.idx_q + 2] = np.cos(value), np.sin(value)
        return
    if joint.nq != 1:
        raise InputError(f"locked: joint {jname!r} has {joint.nq} coordinates, not one")
    limits = outside_limits(model, joint.idx_q, value)
    if limits is not None:
        raise InputError(
            f"locked: joint {jname!r} = {value:.4g} is outside its limits "
            f"[{limits[0]:.4g}, {limits[1]:.4g}]"
        )
    q[joint.idx_q] = value


def mimic_relations(urdf: str | Path) -> dict[str, tuple[str, float, float]]:
    """{follower: (master, multiplier, offset)} of the ``<mimic>`` joints of a URDF file
    (follower = multiplier · master + offset); empty when the file cannot be read."""
    try:
        root = ET.fromstring(read_input(urdf, "urdf"))
    except (InputError, ValueError, ET.ParseError):
        return {}
    out = {}
    for joint in root.iter("joint"):
        mimic = joint.find("mimic")
        if mimic is not None:
            try:
                factor = float(mimic.get("multiplier", 1.0))
                offset = float(mimic.get("offset", 0.0))
            except ValueError as e:
                raise InputError(f"urdf: the <mimic> of joint {joint.get('name')!r}: {e}") from e
            out[joint.get("name")] = (mimic.get("joint"), factor, offset)
    return out


def lock_mimics(model: pin.Model, q: np.ndarray, urdf: str | Path, given) -> None:
    """Set every locked ``<mimic>`` follower of ``q`` (the full model's configuration, in
    place) to multiplier · master + offset: unlisted followers take it, listed ones must equal
    it (InputError otherwise: the URDF's robot would not be the one planned)."""
    for follower, (master, factor, offset) in mimic_relations(urdf).items():
        if not (model.existJointName(follower) and model.existJointName(master)):
            continue
        jf, jm = (model.joints[model.getJointId(n)] for n in (follower, master))
        if jf.nq != 1 or jm.nq != 1:
            continue
        value = factor * q[jm.idx_q] + offset
        if follower in given and abs(q[jf.idx_q] - value) > 1e-9 * (1 + abs(value)):
            raise InputError(
                f"locked: joint {follower!r} mimics {master!r} ({follower} = {factor:g} · "
                f"{master} + {offset:g} = {value:.6g}) but is locked at {q[jf.idx_q]:.6g}; "
                f"lock it at {value:.6g} or leave it out"
            )
        limits = outside_limits(model, jf.idx_q, value)
        if limits is not None:
            lo, hi = limits
            raise InputError(
                f"locked: joint {follower!r} mimics {master!r} and would sit at {value:.6g}, "
                f"outside its limits [{lo:.4g}, {hi:.4g}]; lock {master!r} elsewhere"
            )
        q[jf.idx_q] = value
