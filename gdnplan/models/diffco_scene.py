"""The scene a DiffCo belongs to: its robot's kinematics and its obstacle layout.

DiffCo (:mod:`gdnplan.models.diffco`) learns one environment: its support points and weights
classify configurations of the robot it was trained for among the obstacles it was trained
among. A scene of another robot is refused (:func:`same_kinematics`); so is a scene whose
obstacles differ from the recorded layout (:func:`layout_difference`), by this rule:

    the same number of obstacle polygons, in the same order, each with the same number of
    vertices in the same order, every vertex coordinate within ``LAYOUT_TOL`` = 1e-6 m of the
    recorded one.

The tolerance admits the rounding of a layout stored as float32 (a compact dataset shard:
≤ 2.4e-7 m for coordinates within 4 m) and nothing a planner could tell apart; a polygon
listed from another first vertex counts as different. The score of a stale layout is asked
for explicitly (:meth:`~gdnplan.models.diffco.DiffCo.ignoring_obstacles`).
"""

from __future__ import annotations

import numpy as np

from ..errors import InputError
from ..robot import Robot

LAYOUT_TOL = 1e-6  # m: largest coordinate difference of one layout's vertices


def same_kinematics(a: Robot, b: Robot) -> bool:
    """True when robots ``a`` and ``b`` have one name, joint count, limits and node positions
    (DiffCo's control points) at their lower, upper and middle configurations."""
    if a is b:
        return True
    if (a.name, a.dof, a.n_nodes) != (b.name, b.dof, b.n_nodes):
        return False
    if not (np.array_equal(a.lower, b.lower) and np.array_equal(a.upper, b.upper)):
        return False
    probe = np.stack([a.lower, a.upper, (a.lower + a.upper) / 2])
    return bool(np.array_equal(a.node_positions(probe), b.node_positions(probe)))


def layout_of(obstacles) -> tuple[np.ndarray, ...]:
    """Obstacle polygons (m_i, 2) (m), e.g. a scene's ``obstacles``, as read-only float64
    copies: a later change to the scene's arrays does not change the record."""
    out = []
    for poly in obstacles:
        copy = np.array(poly, dtype=float)
        copy.setflags(write=False)
        out.append(copy)
    return tuple(out)


def layout_difference(recorded: tuple[np.ndarray, ...], obstacles) -> str | None:
    """None when ``obstacles`` (polygons (m_i, 2), m) are the ``recorded`` layout by the module
    docstring's rule, else how they differ (the first difference found)."""
    if len(obstacles) != len(recorded):
        return (
            f"the scene has {len(obstacles)} obstacle polygons, the training scene {len(recorded)}"
        )
    for j, (have, mine) in enumerate(zip(obstacles, recorded, strict=True)):
        have = np.asarray(have, dtype=float)
        if have.shape != mine.shape:
            return f"obstacle {j} has {len(have)} vertices, in the training scene {len(mine)}"
        gap = float(np.max(np.abs(have - mine), initial=0.0))
        if not gap <= LAYOUT_TOL:  # NaN differs too
            return f"obstacle {j} is {gap:.3g} m from its place in the training scene"
    return None


def dataset_difference(
    recorded: tuple[np.ndarray, ...], obstacles: np.ndarray, sizes: np.ndarray
) -> tuple[int, str] | None:
    """The first sample whose layout differs from ``recorded`` (and how), or None.

    Args:
        recorded: the training layout, polygons (m_i, 2) (m).
        obstacles: (n, P, V, 2) zero-padded polygons of n samples (m), as in
            :class:`gdnplan.data.Dataset`; a slot of size 0 holds no polygon.
        sizes: (n, P) vertex counts.
    """
    sizes = np.asarray(sizes)
    if len(sizes) == 0:
        return None
    lengths = [len(p) for p in recorded]
    patterns, inverse = np.unique(sizes, axis=0, return_inverse=True)
    inverse = inverse.reshape(-1)
    for g, pattern in enumerate(patterns):
        rows = np.flatnonzero(inverse == g)
        slots = np.flatnonzero(pattern > 0)
        if pattern[slots].tolist() != lengths:
            count = [int(s) for s in pattern[slots]]
            return int(rows[0]), (
                f"its obstacles have {count} vertices, the training scene's {lengths}"
            )
        for j, (slot, mine) in enumerate(zip(slots, recorded, strict=True)):
            have = np.asarray(obstacles[rows, slot, : len(mine)], dtype=float)
            gap = np.abs(have - mine).max(axis=(1, 2), initial=0.0)
            bad = np.flatnonzero(~(gap <= LAYOUT_TOL))  # NaN differs too
            if len(bad):
                i = bad[0]
                return int(rows[i]), (
                    f"its obstacle {j} is {gap[i]:.3g} m from its place in the training scene"
                )
    return None


def unknown_layout_error() -> InputError:
    """The refusal of a DiffCo that records no layout (built directly, not trained)."""
    return InputError(
        "scene: this DiffCo does not record the obstacles it was trained among (built "
        "directly, not by DiffCo.train); pass obstacles=<the training scene's obstacles> when "
        "building it, or evaluate it anyway with model.ignoring_obstacles()"
    )


def stale_layout_error(where: str, why: str) -> InputError:
    """The refusal of a scene (or dataset sample) ``where`` whose layout differs: ``why``."""
    return InputError(
        f"{where}: this DiffCo was trained among other obstacles ({why}; the rule: the same "
        f"polygons in order, every vertex within {LAYOUT_TOL:g} m), so its score would be the "
        "training scene's. Adapt it to this scene with model.adapt(scene) (active learning), "
        "train one in it with DiffCo.train(scene), or evaluate the trained layout anyway with "
        "model.ignoring_obstacles()"
    )


__all__ = [
    "LAYOUT_TOL",
    "dataset_difference",
    "layout_difference",
    "layout_of",
    "same_kinematics",
    "stale_layout_error",
    "unknown_layout_error",
]
