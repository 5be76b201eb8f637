"""Checks of mesh files before Pinocchio or coal compute with them: a URDF's collision
meshes (:func:`check_meshes`) and any mesh file (:func:`check_mesh_file`).

Each ``<mesh filename>`` is resolved as Pinocchio resolves it (``package://`` and relative
paths against the package folders, then ``ROS_PACKAGE_PATH`` and ``AMENT_PREFIX_PATH``/share;
``file://`` and absolute paths as they are) and must be a regular file that assimp reads as a
mesh (STL, OBJ, DAE, …), with at least one vertex, every vertex finite and, scaled, within
``MAX_OFFSET`` m of the link frame. Before assimp reads a file whole, its size is checked
(:func:`check_mesh_size`): a binary STL's header gives its triangle count (at most
:data:`MAX_MESH_TRIANGLES`), any mesh file at most :data:`MAX_MESH_BYTES` bytes, so a mesh far
beyond the vertex limit of a hull (:data:`MAX_MESH_VERTICES`, ``arm3d.shapes.MAX_HULL_POINTS``,
checked after reading) is refused without parsing it. The file is read with an axis-aligned
bounding-box tree, which computes nothing with the vertices: coal's default tree runs an
eigen-decomposition on them and prints "eigen: too many iterations" for a NaN. Each failure
is one InputError naming the file, the link and the mesh path.
"""

from __future__ import annotations

import os
import xml.etree.ElementTree as ET
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from ..errors import InputError
from ..files import check_input_file
from .stderr import stderr_captured
from .xml_checks import MAX_OFFSET, mesh_elements, numbers, shown

MAX_MESH_VERTICES = 100_000  # vertices of a mesh's hull: gdnplan.arm3d.shapes.MAX_HULL_POINTS
# A closed triangle mesh of V vertices has about 2 V triangles: twice that is read at all (a
# binary STL of 400 000 triangles, 20 MB, reads in about 1.5 s), more refused from the header.
MAX_MESH_TRIANGLES = 4 * MAX_MESH_VERTICES
# Any mesh file: 32 MiB (a text OBJ or DAE of 100 000 vertices with normals takes ~15 MB;
# assimp reads 32 MiB of OBJ in about 5 s).
MAX_MESH_BYTES = 32 << 20
_STL_HEADER = 84  # bytes: 80 of text, then the triangle count (uint32, little-endian)
_STL_TRIANGLE = 50  # bytes per triangle: normal, 3 vertices (float32), attribute (uint16)
_SIMPLIFY = "simplify (decimate) the mesh or give its convex hull (only the hull is used)"


def mesh_search_dirs(package_dirs: Sequence[str]) -> list[str]:
    """The folders Pinocchio searches for ``package://`` and relative mesh paths, in order."""
    ros = [d for d in os.environ.get("ROS_PACKAGE_PATH", "").split(":") if d]
    ament = [f"{d}/share" for d in os.environ.get("AMENT_PREFIX_PATH", "").split(":") if d]
    return [*package_dirs, *ros, *ament]


def resolve_mesh(filename: str, dirs: Sequence[str]) -> Path | None:
    """The path Pinocchio would load for ``filename`` (None: found in no folder); InputError
    for a scheme other than ``package://``, ``model://`` and ``file://``."""
    scheme, sep, rest = filename.partition("://")
    if sep and scheme not in ("package", "model", "file"):
        raise InputError(f"scheme {scheme!r}:// is not supported (package://, file:// or a path)")
    if sep and scheme == "file":
        return Path(rest)
    relative = rest if sep else filename
    if not sep and Path(filename).is_absolute():
        return Path(filename)
    for folder in dirs:
        candidate = Path(f"{folder}/{relative}")
        if candidate.exists():
            return candidate
    return None


def check_meshes(root: ET.Element, path: Path, package_dirs: Sequence[str]) -> None:
    """InputError naming the first collision mesh of the URDF that is missing, not a file,
    not a mesh, or has a non-finite or far vertex (the module docstring)."""
    dirs = mesh_search_dirs(package_dirs)
    for link, mesh in mesh_elements(root):
        filename = mesh.get("filename", "").strip()
        where = f"urdf: {path.name}: link {shown(link)} <mesh filename={shown(filename)}>"
        try:
            found = resolve_mesh(filename, dirs)
        except InputError as e:
            raise InputError(f"{where}: {e}") from e
        scale = numbers(mesh.get("scale", "1 1 1"), 3, f"{where} scale")
        check_mesh_file(found, scale, where)


def check_mesh_file(found: Path | None, scale: Sequence[float], where: str) -> None:
    """InputError "<where>: …" unless ``found`` is a regular mesh file whose vertices pass
    :func:`mesh_vertices`."""
    if found is None or not found.exists():
        raise InputError(f"{where}: the file does not exist (searched the package folders)")
    mesh_vertices(found, scale, where)


def mesh_vertices(found: Path, scale: Sequence[float], where: str) -> np.ndarray:
    """(k, 3) vertices (m) of the mesh file ``found`` times ``scale`` (3 factors); InputError
    "<where>: …" unless it is a regular mesh file with at least one vertex, every vertex
    finite and within ``MAX_OFFSET`` m. Nothing computes with the vertices before they pass
    (no "eigen: …" noise on stderr)."""
    if found.is_dir():
        raise InputError(f"{where}: {found} is a directory, not a mesh file")
    if not found.is_file():
        raise InputError(f"{where}: {found} is not a regular file (a device or a pipe)")
    check_input_file(found, where)  # at most MAX_INPUT_BYTES: assimp reads it whole
    check_mesh_size(found, where)
    vertices = _read_vertices(found, scale, where)
    if len(vertices) == 0:
        raise InputError(f"{where}: {found} has no vertices")
    bad = np.flatnonzero(~np.all(np.isfinite(vertices), axis=1))
    if len(bad):
        raise InputError(f"{where}: vertex {int(bad[0])} of {found} is NaN or infinite")
    if np.max(np.abs(vertices)) > MAX_OFFSET:
        raise InputError(
            f"{where}: {found} has vertices beyond {MAX_OFFSET:g} m of the link frame "
            f"(scale {scale}); give the mesh in metres or a scale"
        )
    return vertices


def check_mesh_size(found: Path, where: str) -> None:
    """InputError "<where>: …" when the mesh file ``found`` is too large to read (module
    docstring): a binary STL whose header counts more than :data:`MAX_MESH_TRIANGLES`
    triangles, any file of more than :data:`MAX_MESH_BYTES` bytes. Reads 84 bytes at most."""
    try:
        size = found.stat().st_size
        with open(found, "rb") as f:
            head = f.read(_STL_HEADER)
    except OSError as e:
        raise InputError(f"{where}: cannot read {found} ({e.strerror or e})") from e
    if len(head) == _STL_HEADER:
        triangles = int.from_bytes(head[80:], "little")
        if size == _STL_HEADER + _STL_TRIANGLE * triangles and triangles > MAX_MESH_TRIANGLES:
            raise InputError(
                f"{where}: {found} is a binary STL of {triangles} triangles, more than "
                f"{MAX_MESH_TRIANGLES} (a closed mesh of the {MAX_MESH_VERTICES}-vertex limit "
                f"has about {2 * MAX_MESH_VERTICES}); {_SIMPLIFY}"
            )
    if size > MAX_MESH_BYTES:
        raise InputError(
            f"{where}: {found} has {size} bytes, more than {MAX_MESH_BYTES} "
            f"({MAX_MESH_BYTES >> 20} MiB: a mesh of the {MAX_MESH_VERTICES}-vertex limit "
            f"takes far less); {_SIMPLIFY}"
        )


def _read_vertices(found: Path, scale: Sequence[float], where: str) -> np.ndarray:
    """(k, 3) scaled vertices of a mesh file read by coal's assimp loader (no computation)."""
    import coal

    with stderr_captured():
        try:
            bvh = coal.MeshLoader(coal.BV_AABB).load(str(found), np.asarray(scale, float))
        except (ValueError, RuntimeError) as e:
            raise InputError(
                f"{where}: {found} is not a mesh file assimp can read (STL, OBJ, DAE, ...)"
                f"{_assimp_reason(e)}"
            ) from e
    if bvh.num_vertices == 0:
        return np.zeros((0, 3))
    return np.asarray(bvh.vertices(), float).reshape(-1, 3)


def _assimp_reason(error: Exception) -> str:
    """ " (assimp: <its reason>)" from coal's loader error, the line after "Could not load
    resource …" (e.g. "STL: file is empty. There are no facets defined"); "" without one."""
    lines = [line.strip() for line in str(error).splitlines()]
    for k, line in enumerate(lines[:-1]):
        if "Could not load resource" in line and not lines[k + 1].startswith("Hint:"):
            return f" (assimp: {lines[k + 1][:200]})" if lines[k + 1] else ""
    return ""
