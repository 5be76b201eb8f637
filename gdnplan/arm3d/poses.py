"""Poses of 3-D shapes: a position (3,) in metres and a rotation given as a quaternion
(x, y, z, w), any nonzero length (normalised), or a 3×3 rotation matrix (orthonormal within
``ROTATION_TOLERANCE``, determinant +1).
"""

from __future__ import annotations

import coal
import numpy as np

from ..errors import InputError
from ..limits import is_number
from .shape_numbers import as_vector

ROTATION_TOLERANCE = 1e-6  # largest |RᵀR − I| entry of a rotation matrix
ORTHONORMAL_ROUNDING = 4e-15  # |RᵀR − I| of a float64 rotation (an SVD's is ≤ 1.2e-15)


def as_rotation(rotation, name: str = "rotation") -> np.ndarray:
    """A 3×3 rotation matrix from a quaternion (x, y, z, w) or a matrix; None → identity."""
    if rotation is None:
        return np.eye(3)
    items = np.asarray(rotation, dtype=object)
    if items.shape == (4,):
        quat = as_vector(rotation, 4, name)
        norm = float(np.linalg.norm(quat))
        if norm < 1e-9:
            raise InputError(f"{name}: the quaternion (x, y, z, w) {rotation!r} has zero length")
        x, y, z, w = quat / norm
        return np.array(
            [
                [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
            ]
        )
    if items.shape != (3, 3) or not all(is_number(x) for x in items.ravel()):
        raise InputError(
            f"{name}: expected a quaternion (x, y, z, w) or a 3×3 rotation matrix, got {rotation!r}"
        )
    rot = items.astype(float)
    if not np.all(np.isfinite(rot)):
        raise InputError(f"{name}: contains NaN or infinite values")
    error = float(np.max(np.abs(rot.T @ rot - np.eye(3))))
    if error > ROTATION_TOLERANCE or np.linalg.det(rot) < 0:
        raise InputError(
            f"{name}: not a rotation matrix (|RᵀR − I| = {error:.3g}, det = "
            f"{np.linalg.det(rot):.3g}); give an orthonormal matrix with determinant +1"
        )
    if error <= ORTHONORMAL_ROUNDING:  # a rotation to rounding: kept, so that a matrix read
        return rot  # back from a written problem file is the one written, bit for bit
    u, _, vt = np.linalg.svd(rot)  # nearest exact rotation
    return u @ vt


def as_pose(position=(0.0, 0.0, 0.0), rotation=None, name: str = "pose") -> coal.Transform3s:
    """A coal placement from a position (3,) in metres and a rotation (see :func:`as_rotation`)."""
    p = as_vector(position, 3, f"{name}.position")
    return coal.Transform3s(as_rotation(rotation, f"{name}.rotation"), p)
