"""Random obstacle polygons of the paper's planar environments (:mod:`gdnplan.scene`): squares,
α-shapes, and polygons redrawn until they keep clear of the robot's base.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from shapely.geometry import Point, Polygon

from .errors import InputError
from .geometry import alpha_shape, limit_vertices, square
from .robot import Robot


def clear_of_base(poly: np.ndarray, robot: Robot) -> bool:
    """True when the polygon stays farther than ``robot.base_radius`` from joint 1."""
    base = Point(*robot.chain.joint_origins[0])
    return Polygon(poly).distance(base) > robot.base_radius


def place_clear(
    draw: Callable[[np.random.Generator], np.ndarray], n: int, robot: Robot, rng
) -> list:
    """Draw n polygons, redrawing any that touch the base keep-out circle."""
    out = []
    while len(out) < n:
        poly = draw(rng)
        if clear_of_base(poly, robot):
            out.append(poly)
    return out


def random_squares(robot: Robot, seed: int, n: int = 20) -> list[np.ndarray]:
    """``n`` squares of 0.2 m, centres uniform in [-2, 2]², rotations uniform in [0, π/2), clear
    of the base of ``robot`` (environments c and d)."""
    rng = np.random.default_rng(seed)
    return place_clear(
        lambda g: square(g.uniform(-2, 2, 2), 0.2, g.uniform(0, np.pi / 2)), n, robot, rng
    )


def random_alpha_shape(
    rng: np.random.Generator, size: float = 0.7, alpha: float = 0.6, max_vertices: int = 15
) -> np.ndarray:
    """One α-shape obstacle centred at the origin (paper: 20 points, ≤ 15 connected, α = 0.6).

    20 points uniform in the unit square, α-shape with circumradius bound ``alpha`` (unit
    square units), largest piece, at most ``max_vertices`` vertices, scaled to ``size`` m.
    """
    while True:
        points = rng.uniform(0, 1, (20, 2))
        try:
            poly = limit_vertices(alpha_shape(points, alpha), max_vertices)
        except InputError:
            continue
        return (poly - poly.mean(0)) * size
