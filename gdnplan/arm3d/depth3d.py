"""Proven lower bounds on the signed distance of overlapping 3-D pairs, for the certificate
at a negative margin (:func:`gdnplan.ccd_contact.certify_from_contact`).

coal reports an overlapping pair's penetration depth from EPA (at most 64 iterations at the
request's tolerance). EPA's polytope lies inside the Minkowski difference, so a depth that
stops short is *too small*, and on curved shapes it stops short by more than coal's slack
(:func:`gdnplan.ccd.proven_distance`): a cylinder 11.4 µm into a box was reported 5.8 µm deep,
and over 15 000 cylinder–box pairs 10 µm … 1 mm deep coal's signed distance exceeded the exact
one by up to 7 µm (3.5 times the slack); a pair 3 µm deep came back as 0. A certificate that
compares such values with −allowance then proved "never deeper than 10 µm" for a cylinder
11 µm deep. (A margin ≥ 0 is unaffected: any overlap, however underestimated, is ≤ 0.)

The signed distance of two convex shapes is a 1-Lipschitz function of the translation v of
one of them (the signed distance of v to the boundary of their Minkowski difference), so

    d(S₁, S₂) ≥ d(S₁, S₂ + v) − |v|        for every v.

:func:`verified_pair` takes v = t n, n coal's unit normal from shape 1 to shape 2 and
t = max(−d_coal, 0) + ``SHIFT``: the shifted pair is about ``SHIFT`` apart, where coal's answer
is GJK's separation distance with its proven slack, so the bound is
``proven_distance(d') − t`` — exact up to the slack and (1 − cos θ) t for a normal θ off. If
neither +n nor −n brings the pair at least ``SHIFT`` / 2 apart, the pair's bounding-sphere bound
is used (a valid, loose lower bound). An octree obstacle is a union of boxes: its distance is
the minimum of 1-Lipschitz functions, so the bound holds for it too.
"""

from __future__ import annotations

import coal
import numpy as np

from ..ccd import COAL_SLACK, proven_distance
from .distance3d import checker3d
from .narrow3d import PairTable
from .scene3d import Scene3D

VERIFY_BELOW = 1e-4  # m: pairs coal puts closer than this get the translated bound
SHIFT = 1e-4  # m: how far apart the translated pair is meant to be


def verified_pair(table: PairTable, k: int, tf: np.ndarray) -> float:
    """Proven lower bound (m) on the signed distance of pair k of ``table`` at the shape
    placements ``tf`` (S, 4, 4) (module docstring), without the pair's contact offset."""
    d, _, _, n = table.pair(k, tf)
    tf_a, tf_b = table.pair_poses(k, tf)
    norm = float(np.linalg.norm(n))
    if np.isfinite(d) and np.isfinite(norm) and norm > 0.5:
        t = max(-d, 0.0) + SHIFT
        rotation, translation = tf_b.getRotation(), tf_b.getTranslation()
        for sign in (1.0, -1.0):
            shifted = coal.Transform3s(rotation, translation + sign * t * n / norm)
            res = coal.DistanceResult()
            table.functors[k](tf_a, shifted, table.request, res)
            apart = float(res.min_distance)
            if np.isfinite(apart) and apart >= SHIFT / 2:
                return float(proven_distance(apart, table.swept_max)) - t
    return float(table._sphere_bound(k, tf_a, tf_b)[0])


def contact_distances3d(scene: Scene3D, q: np.ndarray, margin: float) -> np.ndarray:
    """(B,) the values c(q) = min_k (d_k + o_k) of configurations q (B, dof) (rad) with
    contact offset ``margin`` (:mod:`gdnplan.arm3d.narrow3d`), lowered wherever a pair coal
    puts closer than ``VERIFY_BELOW`` has a smaller :func:`verified_pair` bound; so
    ``proven_distance`` of the result is a proven lower bound on c even when pairs overlap
    (module docstring). Pairs apart by more keep coal's distance and its slack."""
    table = checker3d(scene)
    q = scene.robot.check_q(q)
    out = table.evaluate(q, contact_offset=margin).distance.copy()
    near, _ = table.pair_distances(q, cap=VERIFY_BELOW)
    offsets = table.offsets(margin)
    tf, _ = table.placements_batch(q)
    lift = COAL_SLACK * (1.0 + table.swept_max)  # proven_distance(v + lift) ≤ v
    for i, k in zip(*np.nonzero(near < VERIFY_BELOW), strict=True):
        out[i] = min(out[i], verified_pair(table, int(k), tf[i]) + offsets[k] + lift)
    return out


__all__ = ["SHIFT", "VERIFY_BELOW", "contact_distances3d", "verified_pair"]
