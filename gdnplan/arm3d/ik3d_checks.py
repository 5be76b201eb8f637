"""Input checks of the pose IK (:mod:`gdnplan.arm3d.ik3d`): its solver settings and the tool
positions of a Cartesian path, each an :class:`~gdnplan.errors.InputError` naming the argument
before any IK is solved.
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import InputError
from ..limits import check_int, check_number
from .shapes import as_vector

MIN_TOL = 1e-12  # m, rad: smallest position_tol / rotation_tol (the DLS reaches ~1e-14 at 1 m)
MAX_POSITION_TOL = 1.0  # m: largest position_tol (an arm's reach)
MAX_ROTATION_TOL = math.pi  # rad: largest rotation_tol (any orientation is within π)
MAX_POINTS = 10_000  # cartesian_path: positions of one path
MAX_IK_COUNT = 100_000  # restarts, solutions and iterations of one solve_pose_ik call


def check_ik_settings(
    margin: float,
    restarts: int,
    solutions: int,
    iterations: int,
    position_tol: float,
    rotation_tol: float,
) -> None:
    """InputError naming the first setting of :func:`~gdnplan.arm3d.ik3d.solve_pose_ik` out of
    range: ``margin`` finite (m); ``restarts``, ``solutions``, ``iterations`` integers in
    1 … :data:`MAX_IK_COUNT`; ``position_tol`` in [:data:`MIN_TOL`, :data:`MAX_POSITION_TOL`]
    (m), ``rotation_tol`` in [:data:`MIN_TOL`, π] (rad)."""
    check_number(margin, "margin", -np.inf)
    check_int(restarts, "restarts", 1, MAX_IK_COUNT)
    check_int(solutions, "solutions", 1, MAX_IK_COUNT)
    check_int(iterations, "iterations", 1, MAX_IK_COUNT)
    for name, tol, high, unit in (
        ("position_tol", position_tol, MAX_POSITION_TOL, "m"),
        ("rotation_tol", rotation_tol, MAX_ROTATION_TOL, "rad"),
    ):
        if check_number(tol, name, 0.0, strict=True) < MIN_TOL:
            raise InputError(f"{name}: {tol:g} is below {MIN_TOL:g}, what the IK solver reaches")
        if tol > high:
            raise InputError(
                f"{name}: {tol:g} {unit} is over {high:g} {unit}: no pose would be missed; "
                "give the error you accept"
            )


def check_positions(positions) -> np.ndarray:
    """(K, 3) tool positions (m) from one point (3,) or K points, else InputError."""
    try:
        items = np.asarray(positions, dtype=object)
    except ValueError:  # ragged nesting
        items = np.asarray(None, dtype=object)
    if items.shape == (3,):
        items = items[None]
    if items.ndim != 2 or items.shape[1] != 3 or not 1 <= len(items) <= MAX_POINTS:
        raise InputError(
            f"positions: expected (K, 3) points (m), 1 ≤ K ≤ {MAX_POINTS}, got {positions!r}"[:300]
        )
    return np.array([as_vector(list(p), 3, f"positions[{k}]") for k, p in enumerate(items)])


__all__ = ["MAX_IK_COUNT", "MAX_POINTS", "MIN_TOL", "check_ik_settings", "check_positions"]
