"""Joint limits of a URDF: continuous planning joints made revolute within [−π, π], and the
checks of every one-coordinate joint's limits, shared by the planar and the 3-D loader.

* A continuous planning joint becomes revolute with limits [−π, π]. Without a ``<limit>`` it
  gets ``velocity = CONTINUOUS_VELOCITY`` rad/s (timing needs a finite speed; give
  ``<limit effort="…" velocity="…"/>`` in the URDF to choose another) and no effort limit.
* Every revolute or prismatic joint needs finite limits within ``MAX_LIMIT`` (rad, or m for
  a prismatic joint) with lower ≤ upper; a planning joint needs lower < upper.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from collections.abc import Sequence
from pathlib import Path

import numpy as np
import pinocchio as pin

from ..errors import InputError

MAX_LIMIT = 1e3  # rad (m for prismatic): largest |lower| or |upper| of a joint
MIN_RANGE = 1e-6  # rad (m): smallest upper − lower of a planning joint (one that can move)
CONTINUOUS_VELOCITY = 1.0  # rad/s: a continuous planning joint's speed without a <limit>


def make_continuous_revolute(root: ET.Element, planning: Sequence[str]) -> list[str]:
    """Turn the continuous planning joints of ``root`` (in place) into revolute joints limited
    to [−π, π]; the names of those that had no ``<limit>`` (they get the default velocity)."""
    bare = []
    for joint in root.findall("joint"):
        if joint.get("type") != "continuous" or joint.get("name") not in planning:
            continue
        joint.set("type", "revolute")
        limit = joint.find("limit")
        if limit is None:
            limit = ET.SubElement(joint, "limit", effort="0", velocity=repr(CONTINUOUS_VELOCITY))
            bare.append(joint.get("name"))
        limit.set("lower", repr(-np.pi))
        limit.set("upper", repr(np.pi))
    return bare


def unlimit_effort(model: pin.Model, names: Sequence[str]) -> None:
    """No effort limit (inf) for the joints ``names`` (a continuous joint without ``<limit>``)."""
    for name in names:
        model.effortLimit[model.joints[model.getJointId(name)].idx_v] = np.inf


def check_joint_limits(model: pin.Model, planning: Sequence[str], path: Path) -> None:
    """InputError naming the first revolute or prismatic joint of ``model`` whose limits are
    not finite, beyond ``MAX_LIMIT``, or reversed; or a planning joint whose range is below
    ``MIN_RANGE``."""
    for j in range(1, model.njoints):
        joint, name = model.joints[j], model.names[j]
        if joint.nq != 1 or joint.nv != 1:
            continue  # fixed joints are gone; continuous (2 coordinates), floating, planar
        lo = float(model.lowerPositionLimit[joint.idx_q])
        hi = float(model.upperPositionLimit[joint.idx_q])
        unit = "m" if joint.shortname().startswith("JointModelP") else "rad"
        where = f"urdf: {path.name}: joint {name!r} <limit lower={lo:g} upper={hi:g}>"
        if not (np.isfinite(lo) and np.isfinite(hi) and max(abs(lo), abs(hi)) <= MAX_LIMIT):
            raise InputError(
                f"{where}: limits must be finite and within ±{MAX_LIMIT:g} {unit}; give the "
                "joint's real range"
            )
        if lo > hi:
            raise InputError(f"{where}: lower > upper; swap them")
        if hi - lo < MIN_RANGE and name in planning:
            raise InputError(
                f"{where}: a planning joint needs upper − lower ≥ {MIN_RANGE:g} {unit} (it "
                "cannot move); give its range or lock it"
            )
