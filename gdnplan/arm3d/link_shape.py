"""One collision shape of a 3-D robot link (:class:`LinkShape`), checked when made: the
continuous certificate's lever arms and the broad phase trust its bounding sphere; made from a
URDF's Pinocchio geometry object by :func:`link_shape_from_geometry` (URDF primitives stay coal
primitives, meshes become their convex hulls)."""

from __future__ import annotations

from dataclasses import dataclass

import coal
import numpy as np
import pinocchio as pin

from ..errors import InputError
from ..limits import check_int, is_number, read_only
from .shapes import (
    as_pose,
    as_vector,
    bounding_sphere,
    box,
    bvh_vertices,
    capsule,
    check_shape,
    cylinder,
    mesh_hull,
    sphere,
)


@dataclass(frozen=True)
class LinkShape:
    """One collision shape of a robot link.

    Attributes:
        name: the geometry's name (Pinocchio's geometry object name).
        link: the URDF link carrying it.
        body: the joint index (reduced model) the link moves with; 0 = fixed base.
        shape: the coal shape, in its own frame.
        placement: (4, 4) homogeneous placement of the shape frame in the body's joint frame.
        center: (3,) bounding-sphere centre in the shape frame (m); radius: its radius (m).
    """

    name: str
    link: str
    body: int
    shape: coal.CollisionGeometry
    placement: np.ndarray
    center: np.ndarray
    radius: float

    def __post_init__(self) -> None:
        """InputError unless it is a shape :func:`robot3d_from_urdf` could build: string names,
        a body index ≥ 0, a valid coal shape, a rigid placement and a sphere (center, radius)
        enclosing the shape. The certificate's lever arms (:func:`~gdnplan.arm3d.ccd3d.
        lever_arms3d`) and the broad phase trust that sphere: a hand-built 10 cm cube given
        radius 1e-6 m was certified 1 cm clear of a wall its corners turned 1.07 cm into."""
        if not (isinstance(self.name, str) and isinstance(self.link, str)):
            raise InputError(f"LinkShape: name and link must be strings, got {self.name!r}")
        where = f"LinkShape {self.name!r}"
        check_int(self.body, f"{where}.body", 0)
        check_shape(self.shape, where)
        tf = np.asarray(self.placement, dtype=object)
        if tf.shape != (4, 4) or list(tf[3]) != [0, 0, 0, 1]:
            raise InputError(f"{where}.placement: expected a (4, 4) homogeneous transform")
        as_pose(tf[:3, 3], tf[:3, :3], f"{where}.placement")  # finite, a rotation
        center, radius = bounding_sphere(self.shape)
        given = as_vector(self.center, 3, f"{where}.center")
        inside = is_number(self.radius) and (
            np.linalg.norm(given - center) + radius <= self.radius + 1e-9 * (1 + radius)
        )
        if not inside:
            raise InputError(
                f"{where}: center {given.tolist()} and radius {self.radius!r} m do not enclose "
                f"its shape (its bounding sphere: centre {center.round(6).tolist()}, radius "
                f"{radius:.6g} m); use gdnplan.arm3d.shapes.bounding_sphere"
            )
        # read-only copies: the lever arms and the kinematics are cached from them
        object.__setattr__(self, "placement", read_only(tf))
        object.__setattr__(self, "center", read_only(given))


def link_shape_from_geometry(model: pin.Model, obj: pin.GeometryObject) -> LinkShape:
    """The validated coal shape of one geometry object (a mesh becomes its convex hull)."""
    g, where = obj.geometry, f"geometry {obj.name!r}"
    if isinstance(g, coal.Box):
        shape = box(2 * np.asarray(g.halfSide), where)
    elif isinstance(g, coal.Sphere):
        shape = sphere(g.radius, where)
    elif isinstance(g, coal.Capsule):
        shape = capsule(g.radius, 2 * g.halfLength, where)
    elif isinstance(g, coal.Cylinder):
        shape = cylinder(g.radius, 2 * g.halfLength, where)
    elif hasattr(g, "vertices") or hasattr(g, "points"):
        shape = mesh_hull(bvh_vertices(g), where)
    else:
        raise InputError(f"{where}: unsupported collision shape {type(g).__name__}")
    center, radius = bounding_sphere(shape)
    return LinkShape(
        name=obj.name,
        link=model.frames[obj.parentFrame].name,
        body=int(obj.parentJoint),
        shape=shape,
        placement=obj.placement.homogeneous.copy(),
        center=center,
        radius=radius,
    )


__all__ = ["LinkShape", "link_shape_from_geometry"]
