"""Reading a URDF into Pinocchio, with the parser's complaint as a one-line InputError."""

from __future__ import annotations

import contextlib
import os
import tempfile
import xml.etree.ElementTree as ET
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pinocchio as pin

from ..errors import InputError, UnknownNameError
from .spec import RobotSpec

AXIS_UNIT_TOLERANCE = 1e-9  # largest | |axis| − 1 | of a joint axis after Pinocchio's parse
MAX_OFFSET = 1e3  # m: largest |coordinate| of a joint origin or a collision origin


def load_urdf(spec: RobotSpec) -> tuple[pin.Model, pin.GeometryModel]:
    """Pinocchio model and collision geometry of ``spec.urdf``.

    Continuous planning joints become revolute joints limited to [−π, π] (Pinocchio gives a
    continuous joint two coordinates, cos θ and sin θ). UnknownNameError for a missing file;
    InputError for one that does not parse, with the parser's first complaint, and for a
    planning joint that is a ``<mimic>`` joint or is mimicked (:func:`check_mimic`).
    """
    path = Path(spec.urdf)
    try:
        found = path.is_file()
    except (OSError, ValueError):  # a name too long, a NUL byte
        found = False
    if not found:
        raise UnknownNameError(f"urdf: file {path} does not exist (or is not a file)")
    try:
        root = ET.fromstring(path.read_bytes())
    except (OSError, ET.ParseError) as e:
        reason = str(e).splitlines()[0] if str(e) else type(e).__name__
        raise InputError(f"urdf: {path} is not a readable XML file ({reason})") from e
    _check_mimic(root, spec.planning_joints, path)
    _check_origins(root, path)
    rewritten = False
    for joint in root.iter("joint"):
        if joint.get("type") == "continuous" and joint.get("name") in spec.planning_joints:
            joint.set("type", "revolute")
            limit = joint.find("limit")
            if limit is None:
                limit = ET.SubElement(joint, "limit", effort="0", velocity="0")
            limit.set("lower", repr(-np.pi))
            limit.set("upper", repr(np.pi))
            rewritten = True
    packages = [str(p) for p in spec.package_dirs] + [str(p) for p in path.resolve().parents]
    with _stderr_captured() as log:
        try:
            if rewritten:
                text = ET.tostring(root, encoding="unicode")
                model = pin.buildModelFromXML(text)
                geom = pin.buildGeomFromUrdfString(
                    model, text, pin.GeometryType.COLLISION, package_dirs=packages
                )
            else:
                model = pin.buildModelFromUrdf(str(path))
                geom = pin.buildGeomFromUrdf(
                    model, str(path), pin.GeometryType.COLLISION, package_dirs=packages
                )
        except (ValueError, RuntimeError) as e:
            error = e
        else:
            _check_joint_axes(model, path)
            return model, geom
    reason = next((line.strip() for line in log if line.strip().startswith("Error:")), "")
    reason = (reason.removeprefix("Error:").strip() or str(error) or "no reason given").strip()
    reason = reason.splitlines()[0]
    raise InputError(f"urdf: {path} is not a valid URDF: {reason}") from error


def _check_joint_axes(model: pin.Model, path: Path) -> None:
    """InputError naming the first joint whose axis Pinocchio could not make a unit vector:
    ``<axis xyz="0 0 0"/>`` or one so small its norm underflows (a zero axis never moves; a
    non-unit one turns links by non-rotations, and no distance or certificate holds)."""
    for j in range(1, model.njoints):
        axis = getattr(model.joints[j].extract(), "axis", None)
        if axis is None:
            continue
        norm = float(np.linalg.norm(np.asarray(axis, float)))
        if not abs(norm - 1.0) <= AXIS_UNIT_TOLERANCE:
            raise InputError(
                f"urdf: joint {model.names[j]!r} of {path.name} has the axis "
                f"{np.asarray(axis, float).tolist()}, not a direction; give a nonzero "
                '<axis xyz="x y z"/>'
            )


def _check_origins(root: ET.Element, path: Path) -> None:
    """InputError naming the first joint or collision ``<origin xyz>`` beyond ``MAX_OFFSET``
    along an axis: there floating point loses a link's position (a fixed joint 1e20 m out and
    one −99999999999999999999.4 m back put a link at 0, not 0.6 m) and coal's distances
    overflow, so no certificate would describe the URDF's robot."""
    owners = [(f"joint {j.get('name')!r}", j) for j in root.iter("joint")]
    owners += [(f"a collision of link {k.get('name')!r}", c) for k in root.iter("link")
               for c in k.iter("collision")]  # fmt: skip
    for what, element in owners:
        origin = element.find("origin")
        text = "" if origin is None else origin.get("xyz", "")
        try:
            xyz = np.array([float(x) for x in text.split()])
        except ValueError:
            continue  # urdfdom names the malformed number
        if not np.all(np.abs(xyz) <= MAX_OFFSET):
            raise InputError(
                f"urdf: the origin of {what} in {path.name} is {xyz.tolist()} m, beyond "
                f"{MAX_OFFSET:g} m along an axis; use metres near the robot"
            )


def check_mimic(urdf: str | Path, planning) -> None:
    """InputError when a planning joint of the URDF file is a ``<mimic>`` joint or mimicked.

    Pinocchio reads a mimic joint as an independent joint, so gdnplan would plan it on its own
    or hold it locked while its master moves: distances and certificates would be those of
    another robot than the URDF describes."""
    _check_mimic(ET.fromstring(Path(urdf).read_bytes()), planning, Path(urdf))


def _check_mimic(root: ET.Element, planning, path: Path) -> None:
    planned = set(planning or ())
    for joint in root.iter("joint"):
        mimic = joint.find("mimic")
        if mimic is None:
            continue
        follower, master = joint.get("name"), mimic.get("joint")
        if follower in planned or master in planned:
            raise InputError(
                f"joints: joint {follower!r} mimics joint {master!r} (<mimic> in {path.name}); "
                "gdnplan moves planning joints independently and would not move them together: "
                "lock both joints, or plan a URDF without the <mimic>"
            )


@contextlib.contextmanager
def _stderr_captured() -> Iterator[list[str]]:
    """Collect what C++ code (urdfdom) writes to file descriptor 2 into a list of lines."""
    lines: list[str] = []
    saved = os.dup(2)
    with tempfile.TemporaryFile(mode="w+") as tmp:
        os.dup2(tmp.fileno(), 2)
        try:
            yield lines
        finally:
            os.dup2(saved, 2)
            os.close(saved)
            tmp.seek(0)
            lines.extend(tmp.read().splitlines())
