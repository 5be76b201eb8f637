"""Path metrics that do not depend on how a path is discretised: joint-space arc length and the
path cost after resampling to T waypoints equally spaced in arc length.

A piecewise-linear joint path q_0 … q_{K−1} (K, dof) has the joint-space arc length

    L = Σ_k ‖q_{k+1} − q_k‖                                              (rad, Euclidean norm)

and is parametrised by arc length s ∈ [0, L]. :func:`resample_arc_length` returns the T points
q(s_i), s_i = i L / (T − 1), i = 0 … T − 1, on the same polyline (linear interpolation inside the
segment holding s_i; the first and last points are q_0 and q_{K−1}). :func:`resampled_cost` is
the path cost of these points,

    C_T = Σ_i ‖q(s_{i+1}) − q(s_i)‖²                                     (rad²).

Each chord is at most the arc between its ends, L / (T − 1), so C_T ≤ L² / (T − 1), with
equality exactly when no vertex bends the path between two resampled points (a straight line
gives L² / (T − 1) however it is discretised). Any T-point discretisation of a path whose chords
sum to L' costs at least L'² / (T − 1) (Cauchy–Schwarz), so paths of different planners, with
different vertex counts, compare on one scale once resampled to the same T.
"""

from __future__ import annotations

import numpy as np

from .errors import InputError
from .limits import check_int


def _path(path) -> np.ndarray:
    """(K, dof) float array of finite numbers, K ≥ 1, else InputError."""
    q = np.asarray(path, dtype=float)
    if q.ndim != 2 or len(q) < 1 or q.shape[1] < 1:
        raise InputError(f"path: expected a (K, dof) array with K ≥ 1, got shape {q.shape}")
    if not np.all(np.isfinite(q)):
        raise InputError("path: contains NaN or inf; give finite joint angles (rad)")
    return q


def path_length(path) -> float:
    """Joint-space arc length L = Σ_k ‖q_{k+1} − q_k‖ of a (K, dof) path (rad)."""
    q = _path(path)
    return float(np.sum(np.linalg.norm(np.diff(q, axis=0), axis=1)))


def resample_arc_length(path, n: int) -> np.ndarray:
    """(n, dof) points on the polyline ``path`` (K, dof) equally spaced in arc length.

    Point i lies at arc length i L / (n − 1) (n ≥ 2); a path of length 0 gives n copies of its
    first point (the last one its last point). Zero-length segments (repeated waypoints) are
    skipped.
    """
    q = _path(path)
    check_int(n, "n", 2, 10**7)
    first, last = q[0].copy(), q[-1].copy()
    seg = np.linalg.norm(np.diff(q, axis=0), axis=1)  # (K−1,)
    s = np.concatenate([[0.0], np.cumsum(seg)])
    total = s[-1]
    if total <= 0.0:  # every point the same (up to underflow of the norms): keep the ends
        out = np.repeat(q[:1], n, axis=0)
        out[-1] = q[-1]
        return out
    targets = np.linspace(0.0, total, n)
    keep = np.concatenate([[True], np.diff(s) > 0.0])  # drop repeated points: s strictly increasing
    q, s = q[keep], s[keep]
    k = np.clip(np.searchsorted(s, targets, side="right") - 1, 0, len(s) - 2)
    w = np.clip((targets - s[k]) / (s[k + 1] - s[k]), 0.0, 1.0)[:, None]
    out = q[k] + w * (q[k + 1] - q[k])
    out[0], out[-1] = first, last
    return out


def resampled_cost(path, n: int) -> float:
    """C_n = Σ_i ‖q(s_{i+1}) − q(s_i)‖² of the path resampled to n points equally spaced in arc
    length (:func:`resample_arc_length`), in rad²."""
    return float(np.sum(np.diff(resample_arc_length(path, n), axis=0) ** 2))


__all__ = ["path_length", "resample_arc_length", "resampled_cost"]
