"""Continuous collision certificates for joint-space segments (conservative advancement).

Along the straight joint-space segment q(s) = q_a + s (q_b − q_a), s ∈ [0, 1], no point of link l
travels farther than δ_l(q_a, q_b) (m; :mod:`gdnplan.ccd_motion`: the lever arms of a planar
robot; :mod:`gdnplan.arm3d.ccd3d`: of a 3-D one), δ = max_l δ_l.
If the robot at q_a is apart from the obstacles by d_a > s δ, no point of the
robot at q(s) can lie in an obstacle closer than d_a − s δ (its preimage at q_a would be closer
than d_a), so d(q(s)) ≥ d_a − s δ, and likewise d(q(s)) ≥ d_b − (1 − s) δ. The larger of the two
is at least their mean:

    d(q(s)) ≥ L(q_a, q_b) = (d_a + d_b − δ) / 2     for every s ∈ [0, 1] when L ≥ 0.   (1)

coal's distances are GJK estimates that stop once the estimate is within a tolerance τ of the
separating-plane lower bound (DistanceRequest.gjk_tolerance). GJK runs on the shapes' cores —
a sphere's centre, a capsule's segment, any shape less its swept-sphere radius — and coal
subtracts the radii ρ = ρ₁ + ρ₂ of the pair afterwards, so the relative tolerance applies to
the cores' distance d + ρ:

    d_coal − d ≤ τ (1 + |d_coal| + ρ)                                           (m)

(a capsule of radius 50 m overestimated by 2.9e-5 m ≈ 0.6 τ (1 + d + ρ) at d ≈ 0.05 m, 14 times
τ (1 + d)). The certificate uses the proven lower bound d̲ = d_coal − ``COAL_SLACK``
(1 + |d_coal| + ρ̄) in place of d (:func:`proven_distance`), with ``COAL_SLACK`` = 2 τ and ρ̄ ≥ ρ
of every pair the scene has (0 for the planar prisms, which have no swept radius; 3-D:
:attr:`gdnplan.arm3d.narrow3d.PairTable.swept_max`). d̲ is increasing in d_coal, so the bound
of the smallest distance is the smallest of the pairs' bounds. (Tests compare coal with
shapely's exact planar distances and with exact capsule–cylinder distances.)

:func:`certify_path` splits every waypoint segment into pieces and bisects (all open pieces per
round, one batched coal call) until every piece is proven by (1) to stay above the margin — or
a checked configuration is within the margin (a counterexample), a piece shrinks below
``MIN_PIECE`` without a proof, or the check budget runs out: all three are failures, never
acceptances. The budget is checked before any coal call: when the initial pieces alone need
more than ``max_checks`` evaluations ((K − 1) · min_splits + 1 for K ≥ 2 waypoints, 2 for one
configuration: both ends of its zero-length piece), the result is
``ok=False`` with ``n_checks=0`` and the reason, nothing evaluated or allocated; ``n_checks``
never exceeds ``max_checks`` and ``ok`` always comes with ``reason == ""``. Pieces are also
bisected until their bound is within ``tol`` of the smallest checked coal distance (raw, not
less its slack: :func:`tight_target`), so the reported lower bound is at most ``tol`` below
the path's true minimum — while the budget
lasts: when the next round would exceed it, the pieces already proven above the margin keep
their looser bound and only the others are bisected further, for the margin alone (a path
proven at the margin is never failed for want of a tight bound: a 40-joint arm's straight
line, proven with ``tol = inf``, failed the planner's final ``tol = 1e-3`` certificate).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import coal
import numpy as np

from .ccd_motion import check_robot as check_robot
from .ccd_motion import lever_arms as lever_arms
from .ccd_motion import motion_bound as motion_bound
from .distance import signed_distance
from .errors import InputError
from .flags import check_flag
from .limits import check_int, check_number, is_number, shown
from .scene import Scene, check_scene

COAL_SLACK = 2 * coal.DistanceRequest().gjk_tolerance  # relative error allowance of coal (m/m)
MIN_PIECE = 1e-9  # m: a piece whose robot points move less than this is not bisected further
MAX_SPLITS = 10_000  # min_splits: initial pieces per waypoint segment (bisection refines them)
MAX_CHECKS = 10**8  # max_checks: coal evaluations of one certificate (hours of coal time)


def proven_distance(d_coal: np.ndarray, swept: float = 0.0) -> np.ndarray:
    """Lower bound d̲ = d_coal − COAL_SLACK (1 + |d_coal| + swept) on the exact distance (m);
    +inf (no obstacles) stays +inf.

    ``swept`` (m, ≥ 0): at least the sum of the swept-sphere radii (sphere and capsule radii)
    of the pair that gave d_coal (module docstring); 0 for shapes without one.
    """
    d_coal = np.asarray(d_coal, float)
    finite = np.where(np.isposinf(d_coal), 0.0, d_coal)
    slack = COAL_SLACK * (1.0 + np.abs(finite) + swept)
    with np.errstate(over="ignore"):  # d_coal near −DBL_MAX: −inf, still a lower bound
        return np.where(np.isposinf(d_coal), np.inf, finite - slack)


@dataclass(frozen=True)
class Certificate:
    """Result of :func:`certify_path`.

    The path's true minimum clearance lies in [lower_bound, min_distance]; when ``ok`` the two
    are at most the requested ``tol`` apart, unless the check budget ran out first (module
    docstring: then ``lower_bound`` is a looser proven bound above the margin).

    Attributes:
        ok: proven: the exact signed distance stays above the margin on the whole continuous
            path (every piece's bound (1) > margin).
        lower_bound: proven lower bound on the signed distance along the whole path (m), the
            smallest bound (1) of all pieces; −inf when ``ok`` is False (nothing is proven).
        min_distance: smallest coal distance over all checked configurations (m): an upper
            bound on the path's minimum, and the counterexample's distance when it is ≤ margin.
        n_checks: coal evaluations made, at most the ``max_checks`` asked for.
        bad_segments: indices of the waypoint segments holding a configuration within the
            margin or a piece left unproven (too small to bisect, or out of check budget).
        reason: why the certificate failed ("" when ``ok``).
    """

    ok: bool
    lower_bound: float
    min_distance: float
    n_checks: int
    bad_segments: tuple[int, ...]
    reason: str = ""


def check_certify_args(
    margin: float, tol: float, min_splits: int, max_checks: int, stop_early: bool
) -> None:
    """InputError naming the first bad argument of a certificate (:func:`certify_path`,
    :func:`gdnplan.arm3d.certify_path3d`): ``stop_early`` is a flag
    (:func:`gdnplan.flags.check_flag`: not 1, not a string, which would be taken as true)."""
    check_number(margin, "margin")
    if not (is_number(tol) and tol > 0) or math.isnan(tol):
        raise InputError(f"tol: expected a number > 0 (m) or inf, got {shown(tol)}")
    check_int(min_splits, "min_splits", 1, MAX_SPLITS)
    check_int(max_checks, "max_checks", 1, MAX_CHECKS)
    check_flag(stop_early, "stop_early")


def check_path(robot, q_path: np.ndarray) -> np.ndarray:
    """The waypoints q_path (K, dof) (rad) of a path to certify, K ≥ 1, checked by ``robot``
    (planar or 3-D: its ``check_q``), else InputError naming ``q_path``."""
    q_path = robot.check_q(q_path, "q_path")
    if not len(q_path):
        raise InputError("q_path: expected at least one waypoint, got none")
    return q_path


def _initial_pieces(q_path: np.ndarray, splits: int):
    """(qa, qb, seg): every waypoint segment split into ``splits`` equal pieces."""
    if len(q_path) == 1:
        return q_path, q_path, np.zeros(1, int)
    s = np.linspace(0.0, 1.0, splits + 1)
    step = (q_path[1:] - q_path[:-1])[:, None]
    starts = (q_path[:-1, None] + s[None, :-1, None] * step).reshape(-1, q_path.shape[1])
    ends = (q_path[:-1, None] + s[None, 1:, None] * step).reshape(-1, q_path.shape[1])
    ends[splits - 1 :: splits] = q_path[1:]  # pieces meet the waypoints exactly
    return starts, ends, np.repeat(np.arange(len(q_path) - 1), splits)


def _over_budget(n_waypoints: int, splits: int, max_checks: int) -> Certificate | None:
    """The failed certificate when the initial pieces of a path of ``n_waypoints`` need more
    than ``max_checks`` coal evaluations (the pieces' ends), else None; nothing is checked."""
    segments = max(n_waypoints - 1, 1)
    needed = (1 if n_waypoints == 1 else segments * splits) + 1  # the pieces' ends
    if needed <= max_checks:
        return None
    reason = (
        f"the check budget ({max_checks} coal evaluations) cannot hold the {needed} checks of "
        f"the initial pieces' ends ({splits} per waypoint segment); raise max_checks or lower "
        "min_splits"
    )
    return Certificate(False, -math.inf, math.inf, 0, tuple(range(segments)), reason)


def certify_path(
    scene: Scene,
    q_path: np.ndarray,
    margin: float = 0.0,
    tol: float = 1e-3,
    min_splits: int = 10,
    stop_early: bool = False,
    max_checks: int = 200_000,
) -> Certificate:
    """Prove that the piecewise-linear joint path q_path (K, dof) keeps coal distance > margin.

    Args:
        scene: robot and obstacles.
        q_path: (K, dof) waypoints (rad); K = 1 checks one configuration.
        margin: clearance to prove (m), finite and ≥ 0.
        tol: bisect until the reported lower bound is within ``tol`` of the smallest checked
            distance (m); ``math.inf`` proves the margin only (fastest, e.g. for edge checks).
        min_splits: pieces each waypoint segment starts with, at most ``MAX_SPLITS``.
        stop_early: return at the first configuration within the margin.
        max_checks: coal evaluations allowed; running out is a failure (also when the
            initial pieces alone exceed it: then ``n_checks`` is 0, module docstring).
    """
    check_scene(scene, use="gdnplan.arm3d.certify_path3d")
    check_certify_args(margin, tol, min_splits, max_checks, stop_early)
    robot = scene.robot
    q_path = check_path(robot, q_path)
    return certify_by_bisection(
        q_path,
        lambda q: signed_distance(scene, q),
        lambda qa, qb: motion_bound(robot, qa, qb),
        margin,
        tol,
        min_splits,
        stop_early,
        max_checks,
    )


def tight_target(raw_min: float, best: float, tol: float) -> float:
    """The bound (m) a piece must reach to count as tight: ``tol`` below the smallest raw coal
    distance checked (the certificate's ``min_distance``, an upper bound on the true minimum:
    GJK overestimates), so ``lower_bound`` is within ``tol`` of the path's true minimum. Tested
    against ``best``, the smallest proven distance (raw less coal's slack), it was off by the
    slack too (a held-out plan: 1.002 mm). Where the slack at the minimum exceeds tol/2
    (distances past ~250 m), only ``best`` − tol/2 is reachable (bounds tend to ``best``)."""
    return min(raw_min - tol, best - tol / 2)


def certify_by_bisection(
    q_path: np.ndarray,
    distance: Callable[[np.ndarray], np.ndarray],
    motion: Callable[[np.ndarray, np.ndarray], np.ndarray],
    margin: float,
    tol: float,
    min_splits: int,
    stop_early: bool,
    max_checks: int,
    swept: float = 0.0,
) -> Certificate:
    """The bisection proof behind :func:`certify_path`, for any robot and distance.

    ``distance(q)`` (B, dof) → (B,) is coal's signed distance (m), made a proven lower bound by
    :func:`proven_distance` with ``swept`` (m: the largest swept-sphere radius sum of a pair),
    and ``motion(qa, qb)`` bounds how far any point of the robot moves between qa and qb
    (B, dof) → (B,) (m); a piece is proven when (d_a + d_b − motion) / 2 > margin (and within
    ``tol`` of the smallest checked distance), else it is bisected. Arguments are checked by
    the caller; ``n_checks`` stays within ``max_checks`` (:func:`_over_budget` before the first
    call).
    """
    failed = _over_budget(len(q_path), min_splits, max_checks)
    if failed is not None:
        return failed
    qa, qb, seg = _initial_pieces(q_path, min_splits)
    nodes = np.concatenate([qa, qb[-1:]])
    raw = distance(nodes)
    d_nodes = proven_distance(raw, swept)
    da, db = d_nodes[:-1], d_nodes[1:]
    n_checks, best, raw_min = len(nodes), float(np.min(d_nodes)), float(np.min(raw))
    lower, bad, reasons = math.inf, set(), []
    while len(qa):
        delta = motion(qa, qb)
        bound = (da + db - delta) / 2
        hit = (da <= margin) | (db <= margin)
        if hit.any():
            bad.update(seg[hit].tolist())
            reasons.append("a checked configuration is within the margin")
            if stop_early:
                break
        close = bound >= tight_target(raw_min, best, tol) if math.isfinite(tol) else True
        proven = ~hit & (bound > margin) & close
        stuck = ~hit & ~proven & (delta < MIN_PIECE)
        if stuck.any():
            bad.update(seg[stuck].tolist())
            reasons.append("a piece too small to bisect has no proof")
        if proven.any():
            lower = min(lower, float(np.min(bound[proven])))
        keep = ~(hit | proven | stuck)
        if n_checks + int(keep.sum()) > max_checks and math.isfinite(tol):
            # no budget left for tightness: pieces already above the margin are proven with
            # their (looser) bound, the rest are bisected for the margin alone (tol = inf)
            loose = keep & (bound > margin)
            if loose.any():
                lower = min(lower, float(np.min(bound[loose])))
            keep, tol = keep & ~loose, math.inf
        if n_checks + int(keep.sum()) > max_checks:
            bad.update(seg[keep].tolist())
            reasons.append(f"the check budget ({max_checks} coal evaluations) ran out")
            break
        qa, qb, da, db, seg = qa[keep], qb[keep], da[keep], db[keep], seg[keep]
        mid = (qa + qb) / 2
        raw = distance(mid) if len(mid) else np.zeros(0)
        dm = proven_distance(raw, swept)
        n_checks += len(mid)
        if len(dm):
            best, raw_min = min(best, float(np.min(dm))), min(raw_min, float(np.min(raw)))
        qa, qb = np.concatenate([qa, mid]), np.concatenate([mid, qb])
        da, db = np.concatenate([da, dm]), np.concatenate([dm, db])
        seg = np.concatenate([seg, seg])
    ok = not bad and not reasons
    reason = "; ".join(dict.fromkeys(reasons))
    return Certificate(
        ok, lower if ok else -math.inf, raw_min, n_checks, tuple(sorted(bad)), reason
    )


def verify_path(scene: Scene, q_path: np.ndarray, margin: float = 0.0) -> tuple[bool, float]:
    """Certified coal check of a joint path (K, dof): (proven to stay above ``margin``, proven
    lower bound on its clearance in m, −inf when not proven)."""
    check_scene(scene, use="gdnplan.arm3d.certify_path3d")
    cert = certify_path(scene, q_path, margin=margin)
    return cert.ok, cert.lower_bound


__all__ = [
    "COAL_SLACK",
    "Certificate",
    "certify_path",
    "lever_arms",
    "motion_bound",
    "proven_distance",
    "verify_path",
]
