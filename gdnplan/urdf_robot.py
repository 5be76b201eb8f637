"""Robots from URDF files: a Pinocchio model reduced to its planning joints, link geometry
projected onto the planning plane.

A :class:`RobotSpec` names the URDF, the planning joints (a serial chain, base to tip), the
values of every other joint and the plane's axes u, v (orthonormal world directions, normal
n = u × v). Every other joint is locked, and at q = 0 each planning joint must turn about
±n: then every robot point moves parallel to the plane and its plane coordinates

    x ↦ (u · (x − o₁), v · (x − o₁)),     o₁ = planning joint 1's world position at q = 0,

move by the plane rotations of :class:`~gdnplan.robot.PlanarChain`. A collision geometry
becomes one link polygon: the convex hull of its surface points (box corners, rings of
cylinders and spheres, mesh vertices) in plane coordinates, simplified to at most
``max_vertices`` vertices by dropping the vertex whose removal loses the least area.
Hand-made polygons (plane coordinates at q = 0) can replace or extend the projected ones.
"""

from __future__ import annotations

import contextlib
import os
import tempfile
import xml.etree.ElementTree as ET
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pinocchio as pin
from scipy.spatial import QhullError

from .errors import InputError, UnknownNameError
from .geometry import check_part, convex_hull, simplify_convex
from .limits import is_number
from .robot import LinkPolygon, Plane, Robot, _joint_axis, apply_se3, robot_names

AXIS_TOLERANCE = 1e-6  # largest sin(angle) between a planning joint's axis and the plane normal
PLANE_TOLERANCE = 1e-3  # largest |cos(angle)| between the given plane axes u and v
REVOLUTE = {"JointModelRX", "JointModelRY", "JointModelRZ", "JointModelRevoluteUnaligned"}
CONTINUOUS = {"JointModelRUBX", "JointModelRUBY", "JointModelRUBZ"}
JOINT_KINDS = {"P": "prismatic", "RUB": "continuous", "FreeFlyer": "floating", "Planar": "planar"}


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


def robot_from_urdf(
    name: str,
    spec: RobotSpec,
    limits: tuple[np.ndarray, np.ndarray] | None = None,
    extra_polygons: Sequence[tuple[str, str, np.ndarray]] = (),
    skip_geometry: Callable[[str], bool] = lambda _: False,
    info: dict | None = None,
) -> Robot:
    """A planar robot from a URDF file: lock the non-planning joints, project link geometry.

    Args:
        name: the robot's name (``Robot.name``); not a shipped robot's name (learned weights
            are matched to robots by name).
        spec: the URDF, planning joints, locked joints and plane (see :class:`RobotSpec`).
        limits: (lower, upper) joint limits (dof,) in rad; the URDF's when None.
        extra_polygons: hand-made link polygons ``(name, frame_name, vertices (m, 2))``,
            convex, in plane coordinates at q = 0, attached to the frame (a link's name).
        skip_geometry: collision geometries whose name it accepts are not projected.
        info: metadata kept in ``Robot.info`` (plus ``urdf``).

    Raises:
        UnknownNameError: a missing URDF, an unknown joint or frame (the message lists them).
        InputError: a URDF that does not parse, planning joints that are not a serial chain of
            revolute joints normal to the plane, degenerate plane axes, empty link polygons.
    """
    if not isinstance(name, str) or not name.strip():
        raise InputError(f"name: expected a robot name, got {name!r}")
    if name in robot_names():
        raise InputError(
            f"name: {name!r} is a shipped robot's name (learned weights are matched by robot "
            "name); choose another name for this URDF robot"
        )
    model, geom = load_urdf(spec)
    return robot_from_models(name, model, geom, spec, limits, extra_polygons, skip_geometry, info)


def robot_from_models(
    name: str,
    model: pin.Model,
    geom: pin.GeometryModel,
    spec: RobotSpec,
    limits: tuple[np.ndarray, np.ndarray] | None = None,
    extra_polygons: Sequence[tuple[str, str, np.ndarray]] = (),
    skip_geometry: Callable[[str], bool] = lambda _: False,
    info: dict | None = None,
    group: Callable[[str], str] | None = None,
) -> Robot:
    """:func:`robot_from_urdf` on an already-built full model and its collision geometry.

    ``spec.urdf`` only names the source in messages and ``info``. ``group`` maps geometry
    names to polygon names: geometries of one group (all on one body) share one polygon, the
    convex hull of their joint projection. Without it every geometry is its own polygon.
    """
    source = Path(spec.urdf).name
    axes = plane_basis(spec.plane_axes)
    _check_options(spec)
    q_ref = _reference_configuration(model, spec, source)
    lock_ids = [j for j in range(1, model.njoints) if model.names[j] not in spec.planning_joints]
    reduced, reduced_geom = pin.buildReducedModel(model, geom, lock_ids, q_ref)
    _check_chain(reduced, spec)

    data = reduced.createData()
    gdata = pin.GeometryData(reduced_geom)
    pin.framesForwardKinematics(reduced, data, np.zeros(reduced.nq))
    pin.updateGeometryPlacements(reduced, data, reduced_geom, gdata)
    plane = Plane(origin=data.oMi[1].translation.copy(), axes=axes)
    _check_axes(reduced, data, plane)

    groups: dict[tuple, tuple[int, list[np.ndarray]]] = {}  # (key, name) -> (frame, points)
    for g, obj in enumerate(reduced_geom.geometryObjects):
        if skip_geometry(obj.name):
            continue
        pts = apply_se3(gdata.oMg[g], geometry_points(obj.geometry))
        key = (g, obj.name) if group is None else (None, group(obj.name))
        frame, clouds = groups.setdefault(key, (obj.parentFrame, []))
        if reduced.frames[frame].parentJoint != reduced.frames[obj.parentFrame].parentJoint:
            raise InputError(f"{name}: geometry {obj.name!r} moves apart from group {key[1]!r}")
        clouds.append(plane.project(pts))
    polygons = []
    for (_, pname), (frame, clouds) in groups.items():
        uv = _projected_polygon(np.concatenate(clouds), spec.max_vertices, pname, source)
        polygons.append(_attach(reduced, data, plane, pname, frame, uv))
    for pname, frame_name, uv in extra_polygons:
        if not reduced.existFrame(frame_name):
            links = [f.name for f in reduced.frames if f.type == pin.FrameType.BODY]
            raise UnknownNameError(
                f"{name}: frame {frame_name!r} does not exist; links of {source}: {links}"
            )
        frame = reduced.getFrameId(frame_name)
        polygons.append(_attach(reduced, data, plane, pname, frame, np.asarray(uv, float)))
    if not polygons:
        raise InputError(
            f"{name}: {source} has no collision geometry to project and no polygons were "
            "given; add <collision> shapes to its links or give link polygons"
        )

    lower = reduced.lowerPositionLimit.copy() if limits is None else np.asarray(limits[0], float)
    upper = reduced.upperPositionLimit.copy() if limits is None else np.asarray(limits[1], float)
    return Robot(
        name=name,
        model=reduced,
        plane=plane,
        polygons=tuple(polygons),
        lower=lower,
        upper=upper,
        base_radius=spec.base_radius,
        info=dict(info or {}, urdf=str(spec.urdf)),
    )


# -------------------------------------------------------------------- checks
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
        if not is_number(value) or not np.isfinite(value):
            raise InputError(f"locked: joint {jname!r} needs a finite number, got {value!r}")
        joint = model.joints[model.getJointId(jname)]
        if joint.nq == 1:
            lo, hi = model.lowerPositionLimit[joint.idx_q], model.upperPositionLimit[joint.idx_q]
            if not lo - 1e-9 <= value <= hi + 1e-9:
                raise InputError(
                    f"locked: joint {jname!r} = {value:.4g} is outside its limits "
                    f"[{lo:.4g}, {hi:.4g}]"
                )
            q_ref[joint.idx_q] = value
        elif joint.shortname() in CONTINUOUS:
            q_ref[joint.idx_q : joint.idx_q + 2] = np.cos(value), np.sin(value)
        else:
            raise InputError(f"locked: joint {jname!r} has {joint.nq} coordinates, not one")
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
        axis = data.oMi[j].rotation @ _joint_axis(reduced, j)
        tilt = float(np.linalg.norm(np.cross(axis, n)))
        if tilt > AXIS_TOLERANCE:
            u, v = (np.round(a, 4).tolist() for a in plane.axes)
            raise InputError(
                f"joints: planning joint {reduced.names[j]!r} turns about the world axis "
                f"{np.round(axis, 4).tolist()} at q = 0, not about the normal of the plane "
                f"u = {u}, v = {v} (sin of the angle {tilt:.3g} > {AXIS_TOLERANCE}); choose "
                "plane axes perpendicular to the joint axes or lock the joint"
            )


def _projected_polygon(uv: np.ndarray, max_vertices: int, name: str, source: str) -> np.ndarray:
    """Simplified convex hull of projected points (k, 2); InputError when it is flat."""
    flat = InputError(
        f"geometry {name!r} of {source} projects to a segment or a point on the plane; "
        "give it thickness across the plane, skip it or give a link polygon instead"
    )
    try:
        poly = simplify_convex(convex_hull(uv), max_vertices)
    except (QhullError, ValueError) as e:
        raise flat from e
    try:
        check_part(poly, f"geometry {name!r}")
    except InputError as e:
        raise flat from e
    return poly


# -------------------------------------------------------------------- loading
def load_urdf(spec: RobotSpec) -> tuple[pin.Model, pin.GeometryModel]:
    """Pinocchio model and collision geometry of ``spec.urdf``.

    Continuous planning joints become revolute joints limited to [−π, π] (Pinocchio gives a
    continuous joint two coordinates, cos θ and sin θ). UnknownNameError for a missing file;
    InputError for one that does not parse, with the parser's first complaint.
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
            return model, geom
    reason = next((line.strip() for line in log if line.strip().startswith("Error:")), "")
    reason = (reason.removeprefix("Error:").strip() or str(error) or "no reason given").strip()
    reason = reason.splitlines()[0]
    raise InputError(f"urdf: {path} is not a valid URDF: {reason}") from error


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


def _attach(model, data, plane: Plane, name: str, frame: int, uv: np.ndarray) -> LinkPolygon:
    """A polygon given at q = 0 in plane coordinates, attached to a frame."""
    joint = model.frames[frame].parentJoint
    local = apply_se3(data.oMf[frame].inverse(), plane.lift(uv))
    return LinkPolygon(
        name=name, body=int(joint), frame=int(frame), vertices0=uv, vertices_frame=local
    )


# -------------------------------------------------------------------- geometry
def geometry_points(geometry, samples: int = 24) -> np.ndarray:
    """Surface points (k, 3) of a coal collision geometry in its own frame.

    Boxes give their corners, cylinders/capsules/spheres rings of ``samples`` points, meshes
    their vertices.
    """
    import coal

    ang = np.linspace(0, 2 * np.pi, samples, endpoint=False)
    ring = np.stack([np.cos(ang), np.sin(ang), np.zeros_like(ang)], 1)
    if isinstance(geometry, coal.Box):
        h = np.asarray(geometry.halfSide)
        corners = np.array(np.meshgrid([-1, 1], [-1, 1], [-1, 1])).reshape(3, -1).T
        return corners * h
    if isinstance(geometry, coal.Sphere):
        return _sphere_points(geometry.radius, ang)
    if isinstance(geometry, (coal.Cylinder, coal.Capsule)):
        r, h = geometry.radius, geometry.halfLength
        pts = [ring * r + [0, 0, z] for z in (-h, h)]
        if isinstance(geometry, coal.Capsule):
            pts += [_sphere_points(r, ang) + np.array([0.0, 0.0, z]) for z in (-h, h)]
        return np.concatenate(pts)
    if hasattr(geometry, "vertices"):  # BVH meshes and convex hulls
        return np.asarray(geometry.vertices())
    if hasattr(geometry, "points"):
        return np.asarray(geometry.points())
    raise InputError(f"geometry: unsupported collision shape {type(geometry).__name__}")


def _sphere_points(radius: float, ang: np.ndarray) -> np.ndarray:
    """Points on three great circles of a sphere: enough for the hull of any projection."""
    c, s, z = np.cos(ang), np.sin(ang), np.zeros_like(ang)
    return radius * np.concatenate(
        [np.stack([c, s, z], 1), np.stack([c, z, s], 1), np.stack([z, c, s], 1)]
    )
