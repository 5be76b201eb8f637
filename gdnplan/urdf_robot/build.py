"""A planar :class:`~gdnplan.robot.Robot` from a URDF or from its built Pinocchio models."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from pathlib import Path

import numpy as np
import pinocchio as pin

from ..errors import InputError, UnknownNameError
from ..limits import shown
from ..robot import LinkPolygon, Plane, Robot, apply_se3, robot_names
from .checks import _check_axes, _check_chain, _check_options, _reference_configuration, plane_basis
from .load import load_urdf
from .shapes import _projected_polygon, geometry_points
from .spec import RobotSpec


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
    if not isinstance(spec, RobotSpec):  # a dict raised AttributeError
        raise InputError(f"spec: expected a gdnplan.RobotSpec, got {type(spec).__name__}")
    _check_extras(extra_polygons, skip_geometry, info)
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
            f"{name}: {source} has no collision geometry to project (<visual> elements are "
            "not read) and no polygons were given; add <collision> shapes to its links or "
            "give link polygons"
        )

    if limits is None:
        lower, upper = reduced.lowerPositionLimit.copy(), reduced.upperPositionLimit.copy()
    elif isinstance(limits, (tuple, list)) and len(limits) == 2:
        lower, upper = limits  # Robot checks them (robot_checks.check_joint_range)
    else:
        raise InputError(f"limits: expected (lower, upper) joint limits, got {shown(limits)}")
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


def _check_extras(extra_polygons, skip_geometry, info) -> None:
    """InputError unless ``extra_polygons`` is a list of (name, frame, vertices) triples,
    ``skip_geometry`` callable and ``info`` a dict or None (each raised its own TypeError or
    ValueError from inside the build)."""
    if not isinstance(extra_polygons, (list, tuple)) or not all(
        isinstance(e, (list, tuple)) and len(e) == 3 for e in extra_polygons
    ):
        raise InputError(
            "extra_polygons: expected a list of (name, frame, vertices (m, 2)) triples, got "
            f"{shown(extra_polygons)}"
        )
    if not callable(skip_geometry):
        raise InputError(
            f"skip_geometry: expected a function name -> bool, got {shown(skip_geometry)}"
        )
    if info is not None and not isinstance(info, dict):
        raise InputError(f"info: expected a dict or None, got {shown(info)}")


def _attach(model, data, plane: Plane, name: str, frame: int, uv: np.ndarray) -> LinkPolygon:
    """A polygon given at q = 0 in plane coordinates, attached to a frame."""
    joint = model.frames[frame].parentJoint
    local = apply_se3(data.oMf[frame].inverse(), plane.lift(uv))
    return LinkPolygon(
        name=name, body=int(joint), frame=int(frame), vertices0=uv, vertices_frame=local
    )
