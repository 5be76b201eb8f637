"""Continuous collision certificate of a cubic joint-space curve (the timed ``smooth`` path).

Bound (1) of :mod:`gdnplan.ccd` needs only that no robot point moves farther than
δ = max_l Σ_j r_{l,j} ∫|q̇_j| ds along a piece (m); the lever arms r bound |p − o_j| at every
configuration, so the bound holds along any joint curve, not only a straight one. The 3-D bound
of :mod:`gdnplan.arm3d.ccd3d` (obstacle pairs and self pairs, Δ) is linear in the same per-joint
travels, so one certificate serves both scene kinds: δ is the scene kind's motion bound
(:func:`gdnplan.exact.motion_bound_of`) with |Δq_j| replaced by ∫|q̇_j| ds, and d the kind's
exact distance (:func:`gdnplan.exact.exact_distance` with the margin, in 3-D self-collision
included, contact-only pairs with the offset of :mod:`gdnplan.arm3d.ccd3d`). A
straight piece has ∫|q̇_j| = |Δq_j|; a cubic
piece p_j(s), s ∈ [s_a, s_b], has the total variation TV_j = Σ_i |p_j(x_{i+1}) − p_j(x_i)| over
x = s_a, the roots of the quadratic p'_j inside the piece, s_b (exact: p_j is monotone between
them). The ends' distances are taken at the curve's values p(s_a), p(s_b) as the PPoly
evaluates them, which at a breakpoint is the next piece's polynomial: a PPoly need not be
continuous, and p_cell(s_b⁻) − p(s_b) is a jump the robot would have to travel too. Each joint's
travel is therefore

    T_j = |p_cell,j(s_a) − p_j(s_a)| + TV_j + |p_cell,j(s_b) − p_j(s_b)|      (rad)

(p_cell the piece's own cubic; the two end terms are the jumps, zero up to rounding for a C⁰
curve such as PCHIP): d is Lipschitz along the straight joint segment bridging a jump with the
same lever arms, so the bound below holds for any PPoly, continuous or not (a discontinuous
curve moving into an obstacle just before a breakpoint and jumping back was certified). With
d̲ the proven coal distance at the piece's ends (:func:`gdnplan.ccd.proven_distance`, with the
scene's swept radius :func:`gdnplan.exact.swept_radius_of`) and δ from T,

    d(p(s)) ≥ (d̲(p(s_a)) + d̲(p(s_b)) − δ) / 2     for every s ∈ [s_a, s_b],

and :func:`certify_curve` bisects pieces in s (never across a knot, where the cubic changes)
until every bound is above the margin and within ``tol`` of the smallest checked distance; a
configuration within the margin, a piece too small to bisect or the check budget running out
is a failure, never an acceptance. Tightness yields first: when a piece cannot be bisected or
the budget would run out, pieces already above the margin are proven with their looser bound
and the rest are bisected for the margin alone (as :func:`gdnplan.ccd.certify_path`: a curve
proven above the margin was refused, and timed ``stop``, for want of a tight bound).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from .ccd import MAX_CHECKS, MAX_SPLITS, MIN_PIECE, proven_distance
from .errors import InputError
from .exact import exact_distance, motion_bound_of, swept_radius_of
from .limits import check_int, check_number
from .scene import Scene, check_scene

if TYPE_CHECKING:
    from scipy.interpolate import PPoly

    from .arm3d.scene3d import Scene3D

CURVE_SPLITS = 4  # pieces each knot interval starts with
CURVE_MAX_CHECKS = 200_000  # coal evaluations allowed


def _travel(curve, sa: np.ndarray, sb: np.ndarray) -> np.ndarray:
    """(N, dof) per-joint travel T_j of the module docstring over pieces [sa, sb] (N,), each
    inside one polynomial interval: the piece's total variation plus the jumps between its cubic
    and the curve's values p(sa), p(sb) at its ends (rad)."""
    cell = np.clip(np.searchsorted(curve.x, sa, side="right") - 1, 0, len(curve.x) - 2)
    c = curve.c[:, cell]  # (4, N, dof)

    def own(s: np.ndarray) -> np.ndarray:  # the piece's cubic at s (N,)
        x = (s - curve.x[cell])[:, None]
        return ((c[0] * x + c[1]) * x + c[2]) * x + c[3]

    jumps = np.abs(own(sa) - curve(sa)) + np.abs(own(sb) - curve(sb))
    return _total_variation(curve, sa, sb) + jumps


def _total_variation(curve, sa: np.ndarray, sb: np.ndarray) -> np.ndarray:
    """(N, dof) exact ∫|p'_j| ds of the cubic PPoly ``curve`` over pieces [sa, sb] (N,), each
    inside one polynomial interval: |Δp| between the ends and the roots of the quadratic p'_j."""
    cell = np.clip(np.searchsorted(curve.x, sa, side="right") - 1, 0, len(curve.x) - 2)
    c = curve.c[:, cell]  # (4, N, dof): p = c0 x³ + c1 x² + c2 x + c3, x = s − x_cell
    xa, xb = (sa - curve.x[cell])[:, None], (sb - curve.x[cell])[:, None]
    qa, qb, qc = 3 * c[0], 2 * c[1], c[2]  # p' = qa x² + qb x + qc
    # stable roots (no cancellation when qa is tiny): h = −(qb + sign(qb) √disc) / 2,
    # r1 = h / qa, r2 = qc / h (qa = 0: r2 = −qc / qb). A negative disc is clamped to 0: the
    # extra point it adds cannot raise the variation above the exact one
    disc = np.maximum(qb**2 - 4 * qa * qc, 0.0)
    h = -0.5 * (qb + np.copysign(np.sqrt(disc), qb))
    with np.errstate(divide="ignore", invalid="ignore"):
        r1 = np.where(qa != 0, h / np.where(qa != 0, qa, 1.0), np.nan)
        r2 = np.where(h != 0, qc / np.where(h != 0, h, 1.0), np.nan)
    pts = np.stack([np.broadcast_to(xa, r1.shape), r1, r2, np.broadcast_to(xb, r1.shape)])
    pts = np.where(np.isfinite(pts) & (pts >= xa) & (pts <= xb), pts, xa)
    pts = np.sort(pts, axis=0)
    val = ((c[0] * pts + c[1]) * pts + c[2]) * pts + c[3]
    return np.sum(np.abs(np.diff(val, axis=0)), axis=0)


@dataclass(frozen=True)
class CurveCertificate:
    """Result of :func:`certify_curve`: ``ok`` proves coal distance > margin on the whole curve;
    ``lower_bound`` the proven bound (m, −inf unless ok); ``n_checks`` coal evaluations, at
    most ``max_checks`` (initial pieces needing more fail before any call, ``n_checks`` 0)."""

    ok: bool
    lower_bound: float
    n_checks: int


def certify_curve(
    scene: Scene | Scene3D,
    curve: PPoly,
    margin: float = 0.0,
    tol: float = 1e-3,
    splits: int = CURVE_SPLITS,
    max_checks: int = CURVE_MAX_CHECKS,
) -> CurveCertificate:
    """Prove that the cubic joint curve p(s) (rad), s ∈ [curve.x[0], curve.x[-1]], keeps the
    coal distance above ``margin`` (m), by the bound of the module docstring.

    Args:
        scene: robot and obstacles, a planar ``Scene`` or a ``Scene3D``.
        curve: a cubic ``scipy.interpolate.PPoly`` (e.g. a PchipInterpolator) of shape (dof,),
            its breakpoints finite and increasing; it may jump at them (module docstring).
        margin: clearance to prove (m), finite and ≥ 0.
        tol: bisect until the proven bound is within ``tol`` of the smallest checked distance
            (m), finite and > 0.
        splits: pieces each knot interval starts with.
        max_checks: coal evaluations allowed; running out is a failure.
    """
    check_scene(scene, "any")
    check_number(margin, "margin")
    check_number(tol, "tol", strict=True)
    check_int(splits, "splits", 1, MAX_SPLITS)
    check_int(max_checks, "max_checks", 1, MAX_CHECKS)
    if curve.c.ndim != 3 or curve.c.shape[0] != 4 or curve.c.shape[2] != scene.robot.dof:
        raise InputError(f"curve: expected a cubic PPoly of {scene.robot.dof} joints")
    if not (np.all(np.isfinite(curve.x)) and np.all(np.diff(curve.x) > 0)):
        raise InputError(  # a descending PPoly: the pieces' cells would be looked up wrongly
            "curve: expected finite, strictly increasing breakpoints (PPoly.x); reverse a "
            "descending curve's parameter"
        )
    robot = scene.robot
    zero = np.zeros(robot.dof)
    x = curve.x
    if (len(x) - 1) * splits + 1 > max_checks:  # the initial nodes alone: fail before any call
        return CurveCertificate(False, -math.inf, 0)
    s = np.linspace(0.0, 1.0, splits + 1)
    nodes = np.unique((x[:-1, None] + s[None] * np.diff(x)[:, None]).ravel())
    nodes = np.unique(np.concatenate([nodes, x]))
    q_nodes = robot.check_q(curve(nodes), "curve")
    swept = swept_radius_of(scene)
    d = proven_distance(exact_distance(scene, q_nodes, margin=margin), swept)
    sa, sb, da, db = nodes[:-1], nodes[1:], d[:-1], d[1:]
    n_checks, lower, best = len(nodes), math.inf, float(np.min(d))
    while len(sa):
        if np.any(da <= margin) or np.any(db <= margin):
            return CurveCertificate(False, -math.inf, n_checks)
        delta = motion_bound_of(robot, zero[None], _travel(curve, sa, sb))
        bound = (da + db - delta) / 2
        proven = (bound > margin) & (bound >= best - tol)
        keep = ~proven
        if math.isfinite(tol) and _cut_short(keep, delta, n_checks, max_checks):
            proven |= keep & (bound > margin)  # above the margin: proven, with a looser bound
            keep, tol = ~proven, math.inf  # the rest: the margin alone
        if proven.any():
            lower = min(lower, float(np.min(bound[proven])))
        if _cut_short(keep, delta, n_checks, max_checks):
            return CurveCertificate(False, -math.inf, n_checks)
        sa, sb, da, db = sa[keep], sb[keep], da[keep], db[keep]
        mid = (sa + sb) / 2
        raw = exact_distance(scene, curve(mid), margin=margin) if len(mid) else mid
        dm = proven_distance(raw, swept)
        n_checks += len(mid)
        best = min(best, float(np.min(dm))) if len(dm) else best
        sa, sb = np.concatenate([sa, mid]), np.concatenate([mid, sb])
        da, db = np.concatenate([da, dm]), np.concatenate([dm, db])
    return CurveCertificate(True, lower, n_checks)


def _cut_short(keep: np.ndarray, delta: np.ndarray, n_checks: int, max_checks: int) -> bool:
    """Whether the pieces ``keep`` cannot all be bisected: one is below MIN_PIECE, or their
    midpoints would exceed the check budget."""
    return bool(np.any(keep & (delta < MIN_PIECE))) or n_checks + int(keep.sum()) > max_checks


__all__ = ["CurveCertificate", "certify_curve"]
