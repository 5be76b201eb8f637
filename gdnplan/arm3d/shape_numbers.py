"""The number checks of 3-D shapes: coordinates, sizes and point sets, before anything reaches coal.

* coordinates and sizes are finite numbers with ``|x| ≤ MAX_COORDINATE`` (m);
* primitive sizes (box sides, radii, lengths) are at least ``MIN_SIZE`` (m);
* coordinates are real numbers: booleans, strings, complex numbers and other objects are
  refused, not converted.

Used by :mod:`gdnplan.arm3d.shapes` (shapes) and :mod:`gdnplan.arm3d.poses` (poses).
"""

from __future__ import annotations

import numpy as np

from ..errors import InputError
from ..limits import is_number

MAX_COORDINATE = 1e3  # m: largest |coordinate| of any point, position or size
MIN_SIZE = 1e-6  # m: smallest primitive size and hull thickness
MAX_HULL_POINTS = 100_000  # points of one convex hull (mesh vertices)


def as_vector(value, n: int, name: str) -> np.ndarray:
    """A finite float (n,) array of numbers bounded by MAX_COORDINATE, else InputError."""
    items = np.asarray(value, dtype=object)
    if items.shape != (n,) or not all(is_number(x) for x in items.ravel()):
        raise InputError(f"{name}: expected {n} numbers, got {value!r}")
    out = items.astype(float)
    if not np.all(np.isfinite(out)):
        raise InputError(f"{name}: contains NaN or infinite values ({value!r})")
    if np.max(np.abs(out)) > MAX_COORDINATE:
        raise InputError(f"{name}: values beyond {MAX_COORDINATE:g} m; use metres near the robot")
    return out


def as_size(value, name: str) -> float:
    """A primitive size (m) in [MIN_SIZE, MAX_COORDINATE], else InputError."""
    if not is_number(value) or not np.isfinite(value) or not MIN_SIZE <= value <= MAX_COORDINATE:
        shown = value.item() if isinstance(value, np.generic) else value  # 0.0, not np.float64(0.0)
        raise InputError(
            f"{name}: expected a size in [{MIN_SIZE:g}, {MAX_COORDINATE:g}] m, got {shown!r}"
        )
    return float(value)


def as_points(
    points, name: str, min_points: int = 4, max_points: int = MAX_HULL_POINTS
) -> np.ndarray:
    """A finite, bounded float (k, 3) point array (min_points ≤ k ≤ max_points; the defaults:
    a convex hull's), else InputError. Coordinates are real numbers: booleans, strings
    (``"0.5"``), complex numbers and other objects are refused, not converted."""
    pts = _real_array(points, name)
    if pts.ndim != 2 or pts.shape[1] != 3 or not min_points <= len(pts) <= max_points:
        raise InputError(
            f"{name}: expected (k, 3) points with {min_points} ≤ k ≤ {max_points}, got {pts.shape}"
        )
    if not np.all(np.isfinite(pts)):
        raise InputError(f"{name}: contains NaN or infinite coordinates")
    if np.max(np.abs(pts)) > MAX_COORDINATE:
        raise InputError(
            f"{name}: coordinates beyond {MAX_COORDINATE:g} m; use metres near the robot"
        )
    return pts


_NOT_REAL = {"b": "booleans", "U": "strings", "S": "bytes", "c": "complex numbers"}


def _real_array(points, name: str) -> np.ndarray:
    """``points`` as a float array when every entry is a real number (numpy kinds integer,
    unsigned or float; a nested list element by element, where numpy would turn ``True`` into
    1.0 silently), else InputError naming ``name``."""
    if isinstance(points, (list, tuple)) or (
        isinstance(points, np.ndarray) and points.dtype.kind == "O"
    ):
        try:
            items = np.asarray(points, dtype=object)
        except ValueError as e:  # a ragged nesting numpy cannot hold
            raise InputError(f"{name}: expected points of shape (k, 3), got a ragged list") from e
        if items.ndim != 2:  # empty, flat or ragged: the caller refuses the shape
            return np.zeros(items.shape)
        bad = [x for x in items.ravel() if not is_number(x)][:1]
        if bad:
            shown = bad[0].item() if isinstance(bad[0], np.generic) else bad[0]
            raise InputError(f"{name}: expected real numbers as coordinates, got {shown!r}")
        return items.astype(float)
    try:
        arr = np.asarray(points)
    except (TypeError, ValueError, RuntimeError) as e:
        raise InputError(f"{name}: expected points of shape (k, 3), got {type(points)}") from e
    if arr.dtype.kind not in "iuf":
        what = _NOT_REAL.get(arr.dtype.kind, f"an array of {arr.dtype}")
        raise InputError(f"{name}: expected real numbers as coordinates, got {what}")
    return arr.astype(float)
