"""Checks of a URDF's XML before urdfdom reads it: every number of a ``<collision>`` element
and of every joint and collision ``<origin>``.

urdfdom drops a ``<collision>`` it cannot parse (a side ``nan``, two numbers for a box, an
unknown shape) with a complaint on stderr only, and ignores what it does not know (a second
``<geometry>``, ``quat_xyzw`` in an ``<origin>``): the robot planned would miss a shape.
Here each of them is an :class:`~gdnplan.errors.InputError` naming the file, the link (or
joint) and the attribute. The rules (what urdfdom reads, plus the limits gdnplan needs):

* numbers are decimal (``-1``, ``0.5``, ``.5``, ``2e-3``), separated by spaces, finite;
* ``<origin>`` (at most one) has only ``xyz`` (3 numbers, each within ``MAX_OFFSET`` m) and
  ``rpy`` (3 numbers, each within ``MAX_ANGLE`` rad);
* a ``<collision>`` has exactly one ``<geometry>`` holding exactly one shape, of the kinds
  in ``SHAPE_SIZES``: box ``size`` (3 sides), sphere ``radius``, cylinder ``radius`` and
  ``length``, each in [``MIN_SIZE``, ``MAX_SIZE``] m; or a mesh with a ``filename`` and an
  optional ``scale`` (3 nonzero factors within ``MAX_SCALE``; the file itself is checked by
  :mod:`gdnplan.urdf_robot.meshes`).

``<visual>`` elements are not read: gdnplan collides only the ``<collision>`` shapes, and a
link with visuals only is simply no obstacle to anything.
"""

from __future__ import annotations

import math
import re
import xml.etree.ElementTree as ET
from pathlib import Path

from ..errors import InputError

MAX_OFFSET = 1e3  # m: largest |coordinate| of a joint origin or a collision origin
MAX_ANGLE = 1e3  # rad: largest |angle| of an origin's rpy (and of a revolute joint limit)
MIN_SIZE = 1e-6  # m: smallest side, radius or length of a collision primitive
MAX_SIZE = 1e3  # m: largest side, radius or length of a collision primitive
MAX_SCALE = 1e3  # largest |factor| of a mesh scale
SHAPE_SIZES = {"box": {"size": 3}, "sphere": {"radius": 1}, "cylinder": {"radius": 1, "length": 1}}
SHAPES = (*SHAPE_SIZES, "mesh")
ORIGIN_KEYS = {"xyz": (MAX_OFFSET, "m"), "rpy": (MAX_ANGLE, "rad")}
_NUMBER = re.compile(r"[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?")


def shown(text: str | None, most: int = 60) -> str:
    """``text`` quoted on one line (repr), cut to about ``most`` characters."""
    out = repr(text)
    return out if len(out) <= most else out[: most - 4] + "...'"


def numbers(text: str | None, count: int, where: str) -> list[float]:
    """``count`` finite numbers from an attribute's ``text`` (separated by spaces), else an
    InputError "<where>: expected …, got …" (``where`` names the file, element and attribute)."""
    wanted = "a finite number" if count == 1 else f"{count} finite numbers separated by spaces"
    if text is None:
        raise InputError(f"{where}: missing; give {wanted}")
    words = [w for w in text.split(" ") if w]
    if len(words) != count or not all(_NUMBER.fullmatch(w) for w in words):
        raise InputError(f"{where}: expected {wanted}, got {shown(text)}")
    values = [float(w) for w in words]
    if not all(math.isfinite(v) for v in values):
        raise InputError(f"{where}: expected {wanted}, got {shown(text)} (not finite)")
    return values


def check_urdf_xml(root: ET.Element, path: Path) -> None:
    """InputError naming the first malformed ``<collision>`` or ``<origin>`` of a URDF (the
    rules of the module docstring)."""
    for joint in root.findall("joint"):
        _check_origin(joint, f"urdf: {path.name}: joint {shown(joint.get('name'))}")
    for link in root.findall("link"):
        collisions = link.findall("collision")
        for k, collision in enumerate(collisions, 1):
            where = f"urdf: {path.name}: link {shown(link.get('name'))} <collision> {k}"
            _check_origin(collision, where)
            _check_geometry(collision, where)


def check_frame_names(root: ET.Element, path: Path) -> None:
    """InputError when a joint and a link share a name: URDF keeps them apart, Pinocchio makes
    a frame of each and then cannot tell them apart (its reduced model raised a ValueError)."""
    links = {link.get("name") for link in root.findall("link")}
    for joint in root.findall("joint"):
        if joint.get("name") in links:
            name = shown(joint.get("name"))
            raise InputError(
                f"urdf: {path.name}: joint {name} and link {name} share a name, which "
                "Pinocchio cannot tell apart; rename one of them"
            )


def collision_counts(root: ET.Element) -> dict[str, int]:
    """{link name: number of its ``<collision>`` elements} (urdfdom reads the direct children
    of ``<robot>`` and of each ``<link>``)."""
    return {link.get("name", ""): len(link.findall("collision")) for link in root.findall("link")}


def mesh_elements(root: ET.Element) -> list[tuple[str, ET.Element]]:
    """(link name, ``<mesh>``) of every collision mesh, in file order."""
    return [
        (link.get("name", ""), mesh)
        for link in root.findall("link")
        for collision in link.findall("collision")
        for mesh in collision.findall("geometry/mesh")
    ]


def _check_origin(owner: ET.Element, where: str) -> None:
    origins = owner.findall("origin")
    if len(origins) > 1:
        raise InputError(f"{where}: {len(origins)} <origin> elements; give at most one")
    if not origins:
        return
    unknown = sorted(set(origins[0].attrib) - set(ORIGIN_KEYS))
    if unknown:
        raise InputError(
            f"{where} <origin>: unknown attribute {shown(unknown[0])} (urdfdom would ignore "
            'it); give the rotation as rpy="roll pitch yaw" (rad)'
        )
    for key, (most, unit) in ORIGIN_KEYS.items():
        if key not in origins[0].attrib:
            continue
        values = numbers(origins[0].get(key), 3, f"{where} <origin {key}>")
        if max(abs(v) for v in values) > most:
            raise InputError(
                f"{where}: the origin of it has {key}={values} {unit}, beyond {most:g} {unit} "
                f"along an axis; use {'metres near the robot' if unit == 'm' else 'radians'}"
            )


def _check_geometry(collision: ET.Element, where: str) -> None:
    geometries = collision.findall("geometry")
    if len(geometries) != 1:
        raise InputError(f"{where}: {len(geometries)} <geometry> elements; give exactly one")
    shapes = list(geometries[0])
    if len(shapes) != 1:
        found = ", ".join(f"<{s.tag}>" for s in shapes) or "none"
        raise InputError(f"{where} <geometry>: expected one shape of {SHAPES}, got {found}")
    shape = shapes[0]
    if shape.tag not in SHAPES:
        raise InputError(
            f"{where} <geometry>: unsupported shape <{shape.tag}>; use one of {SHAPES} "
            "(urdfdom reads no other)"
        )
    if shape.tag == "mesh":
        _check_mesh(shape, where)
        return
    for key, count in SHAPE_SIZES[shape.tag].items():
        spot = f"{where} <{shape.tag} {key}>"
        for value in numbers(shape.get(key), count, spot):
            if not MIN_SIZE <= value <= MAX_SIZE:
                raise InputError(
                    f"{spot}: {shown(shape.get(key))} has a size outside "
                    f"[{MIN_SIZE:g}, {MAX_SIZE:g}] m"
                )


def _check_mesh(mesh: ET.Element, where: str) -> None:
    if not (mesh.get("filename") or "").strip():
        raise InputError(f'{where} <mesh>: no filename; give <mesh filename="..."/>')
    if "scale" in mesh.attrib:
        factors = numbers(mesh.get("scale"), 3, f"{where} <mesh scale>")
        if not all(0 < abs(s) <= MAX_SCALE for s in factors):
            raise InputError(
                f"{where} <mesh scale>: {shown(mesh.get('scale'))} has a factor that is zero "
                f"or beyond {MAX_SCALE:g}; give three nonzero factors"
            )
