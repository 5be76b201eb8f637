"""Checks of mesh files before Pinocchio or coal compute with them: a URDF's collision
meshes (:func:`check_meshes`) and any mesh file (:func:`check_mesh_file`).

Each ``<mesh filename>`` is resolved as Pinocchio resolves it (``package://`` and relative
paths against the package folders, then ``ROS_PACKAGE_PATH`` and ``AMENT_PREFIX_PATH``/share;
``file://`` and absolute paths as they are) and must be a regular file that assimp reads as a
mesh (STL, OBJ, DAE, …), with at least one vertex, every vertex finite and, scaled, within
``MAX_OFFSET`` m of the link frame. The file is read with an axis-aligned bounding-box tree,
which computes nothing with the vertices: coal's default tree runs an eigen-decomposition on
them and prints "eigen: too many iterations" for a NaN. Each failure is one InputError naming
the file, the link and the mesh path.
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
