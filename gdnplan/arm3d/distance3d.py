"""Exact 3-D signed distance of a robot among obstacles and itself, with its exact gradient.

A :class:`Checker3D` scans the pairs of a scene (:mod:`gdnplan.arm3d.narrow3d`: the pair
table, coal's narrow phase and its conventions) for the minimising pair and takes its gradient
∂d/∂q = nᵀ(J(p₂) − J(p₁)) (:mod:`gdnplan.arm3d.gradient3d`). The overall distance is min_k d_k,
a link's distance is the minimum over the pairs it takes part in (a self pair counts for both
links); each takes the gradient of its minimising pair.

Contact-only self pairs (:mod:`gdnplan.arm3d.pairs`) enter with the offset ``contact_offset``
o (m, :meth:`~gdnplan.arm3d.narrow3d.PairTable.offsets`): a result is min_k (d_k + o_k) with
o_k = o on contact-only pairs and 0 on the others, and its gradient is ∂d_k/∂q of the minimising
pair (o_k is a constant). o = 0 gives true signed distances over every checked pair (the public
:func:`signed_distance3d`); o = M, a margin, gives the value to compare with M
(min_k (d_k + o_k) ≥ M ⟺ every pair meets its requirement: the certificate, the planner's
rows); o = +inf leaves contact-only pairs out (:meth:`Checker3D.evaluate`'s default: the pairs a
margin applies to).

Broad phase: every pair has the lower bound b_k = |c₁ − c₂| − r₁ − r₂ ≤ d_k of its bounding
spheres. Pairs are sent to GJK/EPA in increasing order of b_k and only while b_k is below the
current best of a result they could still lower; a pair with b_k ≥ ``cap`` never is. A result
no pair below ``cap`` reaches reports ``cap`` with a zero gradient and pair −1. Without the
broad phase every pair is sent (the same minima when they are below ``cap``). Offsets shift
the bounds alike: b_k + o_k ≤ d_k + o_k.
"""

from __future__ import annotations

import math
import weakref
from dataclasses import dataclass

import numpy as np

from ..flags import check_flag
from ..scene import check_scene
from .gradient3d import pair_gradients
from .narrow3d import PairTable, check_cap, check_offset, check_tolerance
from .scene3d import Scene3D


@dataclass
class Distances3D:
    """Signed distances of a batch of configurations and what produced them.

    Shapes: (B,) for the overall minimum, (B, L) per link (L = robot.n_links).

    Attributes:
        distance: signed distances min_k (d_k + o_k) (m; true distances when the contact
            offset is 0); ``cap`` where no pair below the cap exists.
        gradient: ∂distance/∂q, (B, dof) or (B, L, dof) (m/rad); None unless requested.
        pair: index of the minimising pair into :attr:`Checker3D.pair_names` (−1: capped).
        point1, point2: (..., 3) world witness points of that pair (m); normal: (..., 3) unit
            normal from shape 1 to shape 2 (zero when capped).
        narrow: (B,) pairs sent to the narrow phase (GJK/EPA) per configuration.
    """

    distance: np.ndarray
    gradient: np.ndarray | None
    pair: np.ndarray
    point1: np.ndarray
    point2: np.ndarray
    normal: np.ndarray
    narrow: np.ndarray


class Checker3D(PairTable):
    """The minimum signed distance (overall or per link) of a scene's pairs, with gradients.

    Args:
        scene: the robot and its obstacles.
        tolerance: GJK and EPA tolerance of coal's request (coal's default 1e-6 when None);
            distances are within about ``tolerance · (1 + |d|)`` m of the exact ones.
    """

    def __init__(self, scene: Scene3D, tolerance: float | None = None):
        check_scene(scene, "3d", "gdnplan.distance.CoalChecker")
        super().__init__(scene, tolerance)

    def scan(
        self,
        q: np.ndarray,
        per_link: bool,
        cap: float,
        broad_phase: bool,
        placed=None,
        offsets: np.ndarray | None = None,
    ):
        """Minimising pairs of one configuration: (targets T; T = 1 or L) arrays of distance
        min_k (d_k + o_k), pair, p₁, p₂, n, and the number of narrow-phase calls; ``placed``:
        its (placements, bounds) when already computed (:meth:`placements_batch`);
        ``offsets`` (P,) the o_k (m; None: :meth:`offsets` (+inf), contact-only pairs out)."""
        n_targets = self.robot.n_links if per_link else 1
        tf, bounds = self.placements(q) if placed is None else placed
        offsets = self.offsets(math.inf) if offsets is None else offsets
        bounds = bounds + offsets  # inf − inf never occurs: bounds are finite
        if broad_phase and not per_link:
            return self._scan_min(tf, bounds, cap, offsets)
        best = np.full(n_targets, cap, dtype=float)
        pair = np.full(n_targets, -1, dtype=int)
        p1, p2, nrm = (np.zeros((n_targets, 3)) for _ in range(3))
        order = np.argsort(bounds, kind="stable") if broad_phase else np.arange(self.n_pairs)
        narrow = 0
        for k in order:
            if offsets[k] == math.inf:
                continue  # a contact-only pair left out
            targets = (self.link_a[k], self.link_b[k]) if per_link else (0,)
            targets = [t for t in targets if t >= 0]
            if broad_phase:
                if bounds[k] >= best.max():
                    break  # sorted: no later pair can lower any result
                if all(bounds[k] >= best[t] for t in targets):
                    continue
            d, a, b, n = self.pair(k, tf)
            d += offsets[k]
            narrow += 1
            for t in targets:
                if d < best[t]:
                    best[t], pair[t], p1[t], p2[t], nrm[t] = d, k, a, b, n
        return best, pair, p1, p2, nrm, narrow

    def _scan_min(self, tf: np.ndarray, bounds: np.ndarray, cap: float, offsets: np.ndarray):
        """:meth:`scan` of the overall minimum with the broad phase (the certificate's and the
        seeds' call): the same pairs in the same order, on Python floats; ``bounds`` already
        include the ``offsets``."""
        best, arg, narrow = cap, -1, 0
        witness = (np.zeros(3), np.zeros(3), np.zeros(3))
        below = np.flatnonzero(bounds < cap)
        for k in below[np.argsort(bounds[below], kind="stable")].tolist():
            if bounds[k] >= best:
                break  # sorted: no later pair can lower the minimum
            d, a, b, n = self.pair(k, tf)
            d += float(offsets[k])
            narrow += 1
            if d < best:
                best, arg, witness = d, k, (a, b, n)
        a, b, n = witness
        return np.array([best]), np.array([arg]), a[None], b[None], n[None], narrow

    def gradient(self, q: np.ndarray, pair: np.ndarray, p1, p2, normal) -> np.ndarray:
        """(T, dof) gradients nᵀ(J(p₂) − J(p₁)) of the minimising pairs (0 where pair = −1)."""
        return pair_gradients(self, q, pair, p1, p2, normal)

    # ------------------------------------------------------------------ batches
    def evaluate(
        self,
        q: np.ndarray,
        per_link: bool = False,
        cap: float = np.inf,
        broad_phase: bool = True,
        gradient: bool = False,
        contact_offset: float = math.inf,
    ) -> Distances3D:
        """Signed distances (and gradients) of configurations q (B, dof) or (dof,) in rad.

        ``contact_offset`` o (m) is added to the contact-only pairs' distances (module
        docstring): +inf (default) leaves them out, 0 gives true distances over every checked
        pair, a margin M gives the value to compare with M.
        """
        q = self.robot.check_q(q)
        cap = check_cap(cap)
        per_link, broad_phase, gradient = (
            check_flag(v, n)
            for v, n in (
                (per_link, "per_link"),
                (broad_phase, "broad_phase"),
                (gradient, "gradient"),
            )
        )
        offsets = self.offsets(contact_offset)
        tf, bounds = self.placements_batch(q)
        rows = [
            self.scan(qi, per_link, cap, broad_phase, (tf[i], bounds[i]), offsets)
            for i, qi in enumerate(q)
        ]
        n = (len(q), self.robot.n_links if per_link else 1)  # (B, T), B = 0 included

        def stacked(i: int, tail: tuple = (), dtype=float) -> np.ndarray:
            return np.array([r[i] for r in rows], dtype).reshape(*n, *tail)

        dist, pair = stacked(0), stacked(1, dtype=int)
        p1, p2, nrm = (stacked(i, (3,)) for i in (2, 3, 4))
        narrow = np.array([r[5] for r in rows], dtype=int)
        grad = None
        if gradient:
            grads = [self.gradient(qi, *r[1:5]) for qi, r in zip(q, rows, strict=True)]
            grad = np.array(grads, float).reshape(*n, self.robot.dof)
        squeeze = (lambda a: a[:, 0]) if not per_link else (lambda a: a)
        return Distances3D(
            squeeze(dist),
            None if grad is None else squeeze(grad),
            squeeze(pair),
            squeeze(p1),
            squeeze(p2),
            squeeze(nrm),
            narrow,
        )


_CHECKERS: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def checker3d(scene: Scene3D, tolerance: float | None = None) -> Checker3D:
    """The cached :class:`Checker3D` of a scene (one per tolerance)."""
    check_scene(scene, "3d", "gdnplan.distance.checker")
    tolerance = check_tolerance(tolerance)  # before the cache: a list is no dictionary key
    per_scene = _CHECKERS.setdefault(scene, {})
    if tolerance not in per_scene:
        per_scene[tolerance] = Checker3D(scene, tolerance)
    return per_scene[tolerance]


def signed_distance3d(
    scene: Scene3D, q, per_link: bool = False, cap: float = np.inf, broad_phase: bool = True
) -> np.ndarray:
    """Signed distance (m) of configurations q (B, dof) or (dof,): (B,), or (B, L) per link.

    Positive when free, minus the penetration depth when overlapping, over the obstacle pairs
    and every checked self pair — contact-only pairs included, with their true distance (no
    offset; to compare with a margin M use ``checker3d(scene).evaluate(q,
    contact_offset=M)``); ``cap`` where every pair's lower bound reaches ``cap``.
    """
    check_scene(scene, "3d", "gdnplan.signed_distance")
    return checker3d(scene).evaluate(q, per_link, cap, broad_phase, contact_offset=0.0).distance


def signed_distance3d_and_grad(
    scene: Scene3D, q, per_link: bool = False, cap: float = np.inf, broad_phase: bool = True
) -> tuple[np.ndarray, np.ndarray]:
    """Signed distance (true, contact-only pairs included; :func:`signed_distance3d`) and its
    exact gradient: ((B,), (B, dof)) or ((B, L), (B, L, dof))."""
    check_scene(scene, "3d", "gdnplan.signed_distance_and_grad")
    checker = checker3d(scene)
    res = checker.evaluate(q, per_link, cap, broad_phase, gradient=True, contact_offset=0.0)
    return res.distance, res.gradient


class Coal3DModel:
    """Exact 3-D signed distance from coal as a :class:`~gdnplan.models.DistanceModel`.

    Args:
        contact_offset: o (m) added to the contact-only pairs' distances (module docstring):
            0 (default) gives true signed distances; the planner passes its margin M so that
            its rows d ≥ M also hold contact-only pairs at d ≥ 0.
    """

    name = "coal3d"

    def __init__(self, contact_offset: float = 0.0):
        self.contact_offset = check_offset(contact_offset)

    def with_contact_offset(self, contact_offset: float) -> Coal3DModel:
        """The model with contact-only pairs offset by ``contact_offset`` (m)."""
        return Coal3DModel(contact_offset)

    def distance(self, scene: Scene3D, q: np.ndarray) -> np.ndarray:
        check_scene(scene, "3d", "gdnplan.signed_distance")
        return checker3d(scene).evaluate(q, contact_offset=self.contact_offset).distance

    def distance_and_grad(
        self, scene: Scene3D, q: np.ndarray, per_link: bool = False, cap: float = np.inf
    ) -> tuple[np.ndarray, np.ndarray]:
        """Distances and gradients, overall or ``per_link`` ((B, L), (B, L, dof): the Ipopt
        transcription's one row per link); pairs whose bound reaches ``cap`` (m) are skipped
        and a link with none below it reports ``cap`` with a zero gradient."""
        check_scene(scene, "3d", "gdnplan.signed_distance_and_grad")
        res = checker3d(scene).evaluate(
            q, per_link, cap, gradient=True, contact_offset=self.contact_offset
        )
        return res.distance, res.gradient
