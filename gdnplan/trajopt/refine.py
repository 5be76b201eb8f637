"""Exact rows for refine rounds of a learned model: where the coal certificate rejected a
segment, the check points there are constrained by coal's signed distance instead of the model.

A learned model d̂ overestimates the distance somewhere, and the certificate then rejects the
segments where the true distance d drops below the certified clearance. Raising the model's
bound there by its observed error (d̂ − d) keeps the path away, but the error measured at one
path is not the error after the path moves, and a raised bound pushes the whole neighbourhood
out (a detour). Exact rows replace, at the check points of the rejected segments (and
``raise_window`` segments either side), the row d̂(p_k) ≥ b_k by d_coal(p_k) ≥ b_k: the bound
needs no raise there and is the true distance wherever the path moves; the other check points
keep the learned model.

A learned model also underestimates the distance somewhere (on the fetch layouts: next to the
grasp, fingers around the stick, d̂ ≈ 4 mm where coal finds 24 mm). Where the solve's starting
path has d̂(p_k) < b_k ≤ d_coal(p_k), its row is violated by the model's error alone and Ipopt
spends its iterations pushing the path out of a region that is in fact free (on fetch layout 0,
two of three seeds ran to the iteration cap). :func:`underestimated_segments` marks those
segments (and ``raise_window`` either side) for coal rows before the first solve: the same
bound on the true distance, so the margin rule and the certificate are unchanged. Coal's
gradient is its closest-pair witness gradient
(:func:`gdnplan.distance.signed_distance_and_grad`; in 3-D
:func:`gdnplan.arm3d.signed_distance3d_and_grad`).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ..arm3d.distance3d import Coal3DModel
from ..arm3d.scene3d import Scene3D
from ..distance import signed_distance, signed_distance_and_grad
from ..models import DistanceModel
from ..scene import Scene
from .check_points import (
    _check_point_raise,
    _interpolation_matrix,
    _near_segments,
    _path_parameters,
)


def _exact(scene: Scene | Scene3D, q: np.ndarray, offset: float) -> np.ndarray:
    """Coal's signed distance of the scene's kind (planar or 3-D); 3-D contact-only self pairs
    count as d + ``offset`` (m, the problem's margin: they are held to d ≥ 0,
    :mod:`gdnplan.arm3d.pairs`)."""
    if isinstance(scene, Scene3D):
        return Coal3DModel(contact_offset=offset).distance(scene, q)
    return signed_distance(scene, q)


def _exact_and_grad(
    scene: Scene | Scene3D, q: np.ndarray, offset: float
) -> tuple[np.ndarray, np.ndarray]:
    """Coal's signed distance and witness gradient of the scene's kind (``offset`` as in
    :func:`_exact`)."""
    if isinstance(scene, Scene3D):
        return Coal3DModel(contact_offset=offset).distance_and_grad(scene, q)
    return signed_distance_and_grad(scene, q)


def exact_check_points(splits: np.ndarray, exact: np.ndarray) -> np.ndarray:
    """(K,) bool: the inner check points of ``splits`` (the NLP's distance rows) lying on a
    segment marked in ``exact`` (T − 1,) bool; a waypoint between two segments is exact when
    either is."""
    return _check_point_raise(splits, exact.astype(float)) > 0


class ExactRows:
    """A :class:`~gdnplan.models.DistanceModel` for the NLP's check points: coal at the batch
    positions ``exact`` (K,) bool, ``model`` at the others.

    Only a batch of K configurations (the check points, in order) is split; any other batch
    goes to ``model`` alone. Keeps ``model``'s deferred gradient
    (``distance_deferred_grad``) when it has one.
    """

    def __init__(self, model: DistanceModel, exact: np.ndarray, offset: float = 0.0) -> None:
        self.model, self.exact = model, np.asarray(exact, bool)
        self.offset = offset  # 3-D contact-only pairs: d + offset (the problem's margin)
        self.name = f"{model.name} + coal rows"
        if hasattr(model, "distance_deferred_grad"):
            self.distance_deferred_grad = self._deferred

    def _mask(self, q: np.ndarray) -> np.ndarray:
        return self.exact if len(q) == len(self.exact) else np.zeros(len(q), bool)

    def distance(self, scene: Scene, q: np.ndarray) -> np.ndarray:
        q = np.atleast_2d(q)
        m = self._mask(q)
        d = np.empty(len(q))
        if (~m).any():
            d[~m] = self.model.distance(scene, q[~m])
        if m.any():
            d[m] = _exact(scene, q[m], self.offset)
        return d

    def distance_and_grad(self, scene: Scene, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        q = np.atleast_2d(q)
        m = self._mask(q)
        d, g = np.empty(len(q)), np.empty(q.shape)
        if (~m).any():
            d[~m], g[~m] = self.model.distance_and_grad(scene, q[~m])
        if m.any():
            d[m], g[m] = _exact_and_grad(scene, q[m], self.offset)
        return d, g

    def _deferred(self, scene: Scene, q: np.ndarray) -> tuple[np.ndarray, Callable[[], np.ndarray]]:
        q = np.atleast_2d(q)
        m = self._mask(q)
        d, g_exact = np.empty(len(q)), None
        learned = None
        if (~m).any():
            d[~m], learned = self.model.distance_deferred_grad(scene, q[~m])
        if m.any():
            d[m], g_exact = _exact_and_grad(scene, q[m], self.offset)

        def grad() -> np.ndarray:
            g = np.empty(q.shape)
            if learned is not None:
                g[~m] = learned()
            if g_exact is not None:
                g[m] = g_exact
            return g

        return d, grad


def underestimated_segments(
    scene: Scene | Scene3D,
    model: DistanceModel,
    q: np.ndarray,
    splits: np.ndarray,
    bound: np.ndarray | float,
    window: int | None,
    offset: float = 0.0,
) -> np.ndarray:
    """(T − 1,) bool: the segments of the path q (T, dof) holding an inner check point of
    ``splits`` with d̂(p_k) < b_k ≤ d_coal(p_k) (the model alone violates the bound ``bound``
    (K,) or scalar, m), and ``window`` segments either side of each (all when None); a waypoint
    check point marks both its segments. Costs one model and one coal call on the K points;
    ``offset``: the problem's margin, added to 3-D contact-only pairs (:func:`_exact`)."""
    points = _interpolation_matrix(splits)[1:-1] @ q
    bound = np.broadcast_to(np.asarray(bound, float), (len(points),))
    low = model.distance(scene, points) < bound
    if low.any():
        low[low] = _exact(scene, points[low], offset) >= bound[low]
    if not low.any():
        return np.zeros(len(splits), bool)
    s = _path_parameters(splits)[1:-1][low]
    last = len(splits) - 1
    hits = np.unique(np.concatenate([np.minimum(np.floor(s), last), np.ceil(s) - 1]))
    return _near_segments(hits.astype(int).tolist(), len(splits), window)


def with_exact_rows(
    model: DistanceModel, splits: np.ndarray, exact: np.ndarray, offset: float = 0.0
) -> DistanceModel:
    """``model`` with coal rows at the check points of the segments ``exact`` (T − 1,) bool
    (:class:`ExactRows`; ``offset`` as in :func:`_exact`); ``model`` itself when no segment is
    marked."""
    if not exact.any():
        return model
    return ExactRows(model, exact_check_points(splits, exact), offset)


__all__ = ["ExactRows", "exact_check_points", "underestimated_segments", "with_exact_rows"]
