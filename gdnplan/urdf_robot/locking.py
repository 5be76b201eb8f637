"""Locked joints: their values in the full model's configuration (the reference the reduced
model is built at), shared by the planar (:mod:`gdnplan.urdf_robot.checks`) and 3-D
(:mod:`gdnplan.arm3d.robot3d`) loaders, and the ``<mimic>`` followers among them."""

from __future__ import annotations

import math
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
    (follower = multiplier · master + offset); empty when the file cannot be read. InputError
    for a ``<mimic>`` that names no joint of the file."""
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
    names = {joint.get("name") for joint in root.iter("joint")}
    for follower, (master, _, _) in out.items():
        if master not in names:
            raise InputError(
                f"urdf: the <mimic> of joint {follower!r} names {master!r}, not a joint of "
                f'{Path(urdf).name}; give <mimic joint="…"> an existing joint'
            )
    return out


def lock_mimics(model: pin.Model, q: np.ndarray, urdf: str | Path, given) -> None:
    """Set every locked ``<mimic>`` follower of ``q`` (the full model's configuration, in
    place) to multiplier · master + offset: unlisted followers take it, listed ones must equal
    it (InputError otherwise: the URDF's robot would not be the one planned).

    Followers are set after their masters (a follower of a follower follows the final value,
    whatever the file's order); a continuous joint, follower or master, counts by its angle.
    A ``<mimic>`` naming no joint of the URDF, or a cycle of them, is an InputError."""
    relations = mimic_relations(urdf)
    for follower in mimic_order(relations, Path(urdf).name):
        master, factor, offset = relations[follower]
        if not (model.existJointName(follower) and model.existJointName(master)):
            continue  # a fixed joint: not part of the model
        jf, jm = (model.joints[model.getJointId(n)] for n in (follower, master))
        if jf.nq != 1 and jf.shortname() not in CONTINUOUS:
            continue  # several coordinates (floating, planar): they stay at their neutral value
        value = factor * joint_angle(jm, q) + offset
        _follow(model, q, jf, (follower, master, factor, offset, value), follower in given)


def _follow(model: pin.Model, q: np.ndarray, jf, mimic: tuple, listed: bool) -> None:
    """Write the follower ``jf`` at ``value`` (``mimic`` = follower, master, multiplier,
    offset, value), or check the value it was locked at when ``listed``."""
    follower, master, factor, offset, value = mimic
    current = joint_angle(jf, q)
    gap = current - value
    if jf.shortname() in CONTINUOUS:
        gap = math.remainder(gap, 2 * math.pi)
    if listed and abs(gap) > 1e-9 * (1 + abs(value)):
        raise InputError(
            f"locked: joint {follower!r} mimics {master!r} ({follower} = {factor:g} · "
            f"{master} + {offset:g} = {value:.6g}) but is locked at {current:.6g}; "
            f"lock it at {value:.6g} or leave it out"
        )
    if jf.shortname() in CONTINUOUS:
        q[jf.idx_q : jf.idx_q + 2] = math.cos(value), math.sin(value)
        return
    limits = outside_limits(model, jf.idx_q, value)
    if limits is not None:
        lo, hi = limits
        raise InputError(
            f"locked: joint {follower!r} mimics {master!r} and would sit at {value:.6g}, "
            f"outside its limits [{lo:.4g}, {hi:.4g}]; lock {master!r} elsewhere"
        )
    q[jf.idx_q] = value


def joint_angle(joint, q: np.ndarray) -> float:
    """The value of a one-coordinate joint in ``q``, or a continuous joint's angle (rad)."""
    if joint.shortname() in CONTINUOUS:
        return math.atan2(q[joint.idx_q + 1], q[joint.idx_q])
    if joint.nq != 1:
        return 0.0
    return float(q[joint.idx_q])


def mimic_order(relations: dict[str, tuple[str, float, float]], source: str) -> list[str]:
    """The followers of ``relations`` ordered so every master that is itself a follower
    comes first; InputError for a cycle of ``<mimic>`` joints."""
    order: list[str] = []
    state: dict[str, int] = {}  # 1: on the current chain, 2: placed
    for start in relations:
        chain = []
        joint = start
        while joint in relations and state.get(joint) != 2:
            if state.get(joint) == 1:
                cycle = " → ".join([*chain[chain.index(joint) :], joint])
                raise InputError(
                    f"urdf: {source}: the <mimic> joints form a cycle ({cycle}); every "
                    "chain of <mimic> joints must end at a joint that mimics none"
                )
            state[joint] = 1
            chain.append(joint)
            joint = relations[joint][0]
        for follower in reversed(chain):
            state[follower] = 2
            order.append(follower)
    return order
