"""Reading a URDF into Pinocchio, with every problem as a one-line InputError.

Before urdfdom reads the file, its XML is checked (:mod:`~gdnplan.urdf_robot.xml_checks`:
every number of the ``<collision>`` elements and of the origins; :mod:`~gdnplan.urdf_robot.meshes`:
the mesh files). After, every link must have as many collision geometries as its XML has
``<collision>`` elements: urdfdom drops an element it cannot parse with a complaint on stderr
only, and a robot missing a shape would be certified collision-free where it is not. Joint
limits are checked by :mod:`~gdnplan.urdf_robot.joint_limits`.
"""

from __future__ import annotations

import os
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pinocchio as pin

from ..errors import InputError, UnknownNameError
from ..files import read_input
from .joint_limits import check_joint_limits, make_continuous_revolute, unlimit_effort
from .meshes import check_meshes
from .spec import RobotSpec
from .stderr import stderr_captured
from .xml_checks import MAX_OFFSET, check_frame_names, check_urdf_xml, collision_counts

AXIS_UNIT_TOLERANCE = 1e-9  # largest | |axis| − 1 | of a joint axis after Pinocchio's parse
__all__ = ["MAX_OFFSET", "check_mimic", "load_urdf", "stderr_captured"]


def urdf_path(urdf: object) -> Path:
    """``urdf`` as a Path when it is a str or path-like, else InputError (Path(3) raised
    TypeError)."""
    if not isinstance(urdf, (str, os.PathLike)):
        raise InputError(f"urdf: expected a file path, got {type(urdf).__name__}")
    return Path(urdf)


def load_urdf(spec: RobotSpec) -> tuple[pin.Model, pin.GeometryModel]:
    """Pinocchio model and collision geometry of ``spec.urdf``.

    Continuous planning joints become revolute joints limited to [−π, π] (Pinocchio gives a
    continuous joint two coordinates, cos θ and sin θ; see
    :mod:`~gdnplan.urdf_robot.joint_limits` for their velocity). UnknownNameError for a
    missing file; InputError for one that does not parse, with the parser's first complaint,
    for a malformed ``<collision>``, origin, mesh file or joint limit (naming the link or
    joint and the attribute), and for a planning joint that is a ``<mimic>`` joint or is
    mimicked (:func:`check_mimic`).
    """
    path = urdf_path(spec.urdf)
    try:
        found = path.is_file()
    except (OSError, ValueError):  # a name too long, a NUL byte
        found = False
    if not found:
        raise UnknownNameError(f"urdf: file {path} does not exist (or is not a file)")
    try:
        root = ET.fromstring(read_input(path, "urdf"))
    except (OSError, ET.ParseError) as e:
        reason = str(e).splitlines()[0] if str(e) else type(e).__name__
        raise InputError(f"urdf: {path} is not a readable XML file ({reason})") from e
    _check_mimic(root, spec.planning_joints, path)
    check_urdf_xml(root, path)
    check_frame_names(root, path)
    packages = [str(p) for p in spec.package_dirs] + [str(p) for p in path.resolve().parents]
    check_meshes(root, path, packages)
    bare = make_continuous_revolute(root, spec.planning_joints)
    model, geom, log = _build(root, path, packages)
    unlimit_effort(model, bare)
    _check_joint_axes(model, path)
    check_joint_limits(model, spec.planning_joints, path)
    _check_counts(root, model, geom, path, log)
    return model, geom


def _build(
    root: ET.Element, path: Path, packages: list[str]
) -> tuple[pin.Model, pin.GeometryModel, list[str]]:
    """The model and collision geometry of the checked XML ``root`` and urdfdom's stderr lines;
    InputError with urdfdom's first complaint when it refuses the file."""
    text = ET.tostring(root, encoding="unicode")
    with stderr_captured() as log:
        try:
            model = pin.buildModelFromXML(text)
            geom = pin.buildGeomFromUrdfString(
                model, text, pin.GeometryType.COLLISION, package_dirs=packages
            )
        except (ValueError, RuntimeError) as e:
            error = e
        else:
            return model, geom, log
    reason = _complaint(log) or str(error).strip() or "no reason given"
    raise InputError(f"urdf: {path} is not a valid URDF: {reason.splitlines()[0]}") from error


def _complaint(log: list[str]) -> str:
    """urdfdom's first "Error:" line without the prefix ("" when there is none)."""
    line = next((x.strip() for x in log if x.strip().startswith("Error:")), "")
    return line.removeprefix("Error:").strip()


def _check_counts(
    root: ET.Element, model: pin.Model, geom: pin.GeometryModel, path: Path, log: list[str]
) -> None:
    """InputError naming the first link with fewer (or more) collision geometries than its
    ``<collision>`` elements: urdfdom dropped one without raising."""
    loaded: dict[str, int] = {}
    for obj in geom.geometryObjects:
        link = model.frames[obj.parentFrame].name
        loaded[link] = loaded.get(link, 0) + 1
    expected = collision_counts(root)
    for link in dict.fromkeys([*expected, *loaded]):
        want, got = expected.get(link, 0), loaded.get(link, 0)
        if want != got:
            reason = _complaint(log) or "no reason given"
            raise InputError(
                f"urdf: {path.name}: link {link!r} has {want} <collision> element(s) but "
                f"{got} reached the collision model (urdfdom: {reason}); fix the element"
            )


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


def check_mimic(urdf: str | Path, planning) -> None:
    """InputError when a planning joint of the URDF file is a ``<mimic>`` joint or mimicked.

    Pinocchio reads a mimic joint as an independent joint, so gdnplan would plan it on its own
    or hold it locked while its master moves: distances and certificates would be those of
    another robot than the URDF describes."""
    _check_mimic(ET.fromstring(read_input(urdf, "urdf")), planning, Path(urdf))


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
