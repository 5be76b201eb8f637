"""Exact 3-D signed distance of a robot among obstacles and itself, with its exact gradient.

The pairs of a :class:`~gdnplan.arm3d.scene3d.Scene3D` are every (robot shape, obstacle) and
every enabled self-collision pair (robot shape, robot shape) of
:attr:`~gdnplan.arm3d.robot3d.Robot3D.self_pairs`. For pair k between shape 1 and shape 2 coal
returns the signed distance d_k (the distance when apart, minus the penetration depth when
overlapping), witness points p₁ (on shape 1), p₂ (on shape 2) and the unit normal n from shape 1
to shape 2, with p₂ − p₁ = d_k n. Moving both shapes rigidly, the first-order change of d_k is
the normal component of the witness points' relative velocity, so

    ∂d_k/∂q = nᵀ (J(p₂) − J(p₁))                                     (1, dof), m/rad

with J(p) (3, dof) the Jacobian of the world point p fixed on its body
(:meth:`~gdnplan.arm3d.robot3d.Robot3D.point_jacobian`, LOCAL_WORLD_ALIGNED; zero for an
obstacle). For an obstacle pair shape 1 is the robot's: ∂d/∂q = −nᵀ J(p₁). The overall distance
is min_k d_k, a link's distance is the minimum over the pairs it takes part in (a self pair
counts for both links); each takes the gradient (1) of its minimising pair. The gradient is
exact wherever that pair and its witness points are unique (away from ties and switches).

Broad phase: every shape has a bounding sphere (centre c, radius r, from coal's local AABB), so
d_k ≥ b_k = |c₁ − c₂| − r₁ − r₂. Pairs are sent to GJK/EPA in increasing order of b_k and only
while b_k is below the current best of a result they could still lower; a pair with b_k ≥ ``cap``
never is. A result no pair below ``cap`` reaches reports ``cap`` with a zero gradient and pair −1.
Without the broad phase every pair is sent (the same minima when they are below ``cap``).

coal's EPA sometimes fails on curved shapes at tight tolerances (it returns −DBL_MAX): such a
pair is recomputed with coal's default request, and if that fails too it reports its
bounding-sphere bound b_k (a lower bound, with a warning on the ``gdnplan.arm3d`` logger).
"""

from __future__ import annotations

import logging
import weakref
from dataclasses import dataclass

import coal
import numpy as np

from ..errors import InputError
from .fk3d import shape_placements_batch
from .robot3d import point_jacobians
from .scene3d import Scene3D

log = logging.getLogger("gdnplan.arm3d")


@dataclass
class Distances3D:
    """Signed distances of a batch of configurations and what produced them.

    Shapes: (B,) for the overall minimum, (B, L) per link (L = robot.n_links).

    Attributes:
        distance: signed distances (m); ``cap`` where no pair below the cap exists.
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


class Checker3D:
    """coal shapes, pair table and distance functors of one 3-D scene, reused across calls.

    Args:
        scene: the robot and its obstacles.
        tolerance: GJK and EPA tolerance of coal's request (coal's default 1e-6 when None);
            distances are within about ``tolerance · (1 + |d|)`` m of the exact ones.
    """

    def __init__(self, scene: Scene3D, tolerance: float | None = None):
        robot = scene.robot
        self.scene, self.robot = scene, robot
        n_shapes, n_obs = len(robot.shapes), len(scene.obstacles)
        obs = np.stack(np.meshgrid(np.arange(n_shapes), np.arange(n_obs), indexing="ij"), -1)
        obs = obs.reshape(-1, 2)
        self.pair_a = np.concatenate([obs[:, 0], robot.self_pairs[:, 0]]).astype(int)
        self.pair_b = np.concatenate([obs[:, 1], robot.self_pairs[:, 1]]).astype(int)
        self.is_self = np.r_[np.zeros(len(obs), bool), np.ones(len(robot.self_pairs), bool)]
        self.link_a = robot.shape_link[self.pair_a]
        self.n_obstacle_pairs = len(obs)  # pairs [0, n_obstacle_pairs) are obstacle pairs
        self_b = robot.self_pairs[:, 1]
        self.link_b = np.r_[np.full(len(obs), -1), robot.shape_link[self_b]].astype(int)
        self.shape_center = np.array([s.center for s in robot.shapes]).reshape(-1, 3)
        self.shape_radius = np.array([s.radius for s in robot.shapes])
        self.obs_center = np.array([o.center for o in scene.obstacles]).reshape(-1, 3)
        obs_radius = np.array([o.radius for o in scene.obstacles])
        self.radius_sum = (
            self.shape_radius[self.pair_a] + np.r_[obs_radius[obs[:, 1]], self.shape_radius[self_b]]
        )
        self.functors = [
            coal.ComputeDistance(
                robot.shapes[a].shape,
                robot.shapes[b].shape if s else scene.obstacles[b].shape,
            )
            for a, b, s in zip(self.pair_a, self.pair_b, self.is_self, strict=True)
        ]
        self.request = coal.DistanceRequest()
        self.request.enable_signed_distance = True
        if tolerance is not None:
            self.request.gjk_tolerance = tolerance
            self.request.epa_tolerance = tolerance
        self.fallback = coal.DistanceRequest()  # coal's defaults: retried when EPA fails
        self.fallback.enable_signed_distance = True
        self.fallbacks = 0  # pairs retried with the fallback request
        self.result = coal.DistanceResult()

    @property
    def n_pairs(self) -> int:
        return len(self.functors)

    def pair_names(self) -> list[tuple[str, str]]:
        """(shape 1, shape 2) names of every pair: ``link/geometry`` or the obstacle's name."""
        shapes, obstacles = self.robot.shapes, self.scene.obstacles
        out = []
        for a, b, s in zip(self.pair_a, self.pair_b, self.is_self, strict=True):
            other = f"{shapes[b].link}/{shapes[b].name}" if s else obstacles[b].name
            out.append((f"{shapes[a].link}/{shapes[a].name}", other))
        return out

    # ------------------------------------------------------------------ one configuration
    def placements(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """World placements (S, 4, 4) of the robot shapes and pair lower bounds b (P,) (m)."""
        tf, bounds = self.placements_batch(np.asarray(q, float)[None])
        return tf[0], bounds[0]

    def placements_batch(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(B, S, 4, 4) shape placements and (B, P) pair lower bounds b (m) of q (B, dof), in
        numpy for the whole batch (:mod:`gdnplan.arm3d.fk3d`)."""
        tf = shape_placements_batch(self.robot, q)
        centers = np.einsum("bsij,sj->bsi", tf[..., :3, :3], self.shape_center) + tf[..., :3, 3]
        m = self.n_obstacle_pairs
        obstacles = np.broadcast_to(self.obs_center[self.pair_b[:m]], (len(q), m, 3))
        other = np.concatenate([obstacles, centers[:, self.pair_b[m:]]], axis=1)
        gap = np.linalg.norm(centers[:, self.pair_a] - other, axis=2)
        return tf, gap - self.radius_sum

    def pair(self, k: int, tf: np.ndarray) -> tuple[float, np.ndarray, np.ndarray, np.ndarray]:
        """Signed distance (m), witness points p₁, p₂ (3,) and normal n (3,) of pair k."""
        a, b = self.pair_a[k], self.pair_b[k]
        tf_a = coal.Transform3s(tf[a, :3, :3], tf[a, :3, 3])
        if self.is_self[k]:
            tf_b = coal.Transform3s(tf[b, :3, :3], tf[b, :3, 3])
        else:
            tf_b = self.scene.obstacles[b].pose
        res = self.result
        res.clear()
        self.functors[k](tf_a, tf_b, self.request, res)
        d = float(res.min_distance)
        if not np.isfinite(d) or d < -self.radius_sum[k]:  # EPA failed (returns −DBL_MAX)
            res.clear()
            self.functors[k](tf_a, tf_b, self.fallback, res)
            d = float(res.min_distance)
            self.fallbacks += 1
            if not np.isfinite(d) or d < -self.radius_sum[k]:
                return self._sphere_bound(k, tf_a, tf_b)
        p1 = np.array(res.getNearestPoint1())
        p2 = np.array(res.getNearestPoint2())
        return d, p1, p2, np.array(res.normal)

    def _sphere_bound(self, k: int, tf_a, tf_b) -> tuple[float, np.ndarray, np.ndarray, np.ndarray]:
        """The bounding-sphere lower bound of pair k with its witnesses (coal failed twice)."""
        log.warning("coal failed on pair %s; using its bounding-sphere bound", self.pair_names()[k])
        a, b = self.pair_a[k], self.pair_b[k]
        ca = tf_a.transform(self.shape_center[a])
        cb = tf_b.transform(self.shape_center[b]) if self.is_self[k] else self.obs_center[b]
        gap = cb - ca
        n = gap / max(np.linalg.norm(gap), 1e-12)
        d = float(np.linalg.norm(gap) - self.radius_sum[k])
        r_a = self.shape_radius[a]
        return d, ca + r_a * n, ca + (r_a + d) * n, n

    def scan(self, q: np.ndarray, per_link: bool, cap: float, broad_phase: bool, placed=None):
        """Minimising pairs of one configuration: (targets T; T = 1 or L) arrays of distance,
        pair, p₁, p₂, n, and the number of narrow-phase calls; ``placed``: its (placements,
        bounds) when already computed (:meth:`placements_batch`)."""
        n_targets = self.robot.n_links if per_link else 1
        tf, bounds = self.placements(q) if placed is None else placed
        if broad_phase and not per_link:
            return self._scan_min(tf, bounds, cap)
        best = np.full(n_targets, cap, dtype=float)
        pair = np.full(n_targets, -1, dtype=int)
        p1, p2, nrm = (np.zeros((n_targets, 3)) for _ in range(3))
        order = np.argsort(bounds, kind="stable") if broad_phase else np.arange(self.n_pairs)
        narrow = 0
        for k in order:
            targets = (self.link_a[k], self.link_b[k]) if per_link else (0,)
            targets = [t for t in targets if t >= 0]
            if broad_phase:
                if bounds[k] >= best.max():
                    break  # sorted: no later pair can lower any result
                if all(bounds[k] >= best[t] for t in targets):
                    continue
            d, a, b, n = self.pair(k, tf)
            narrow += 1
            for t in targets:
                if d < best[t]:
                    best[t], pair[t], p1[t], p2[t], nrm[t] = d, k, a, b, n
        return best, pair, p1, p2, nrm, narrow

    def _scan_min(self, tf: np.ndarray, bounds: np.ndarray, cap: float):
        """:meth:`scan` of the overall minimum with the broad phase (the certificate's and the
        seeds' call): the same pairs in the same order, on Python floats."""
        best, arg, narrow = cap, -1, 0
        witness = (np.zeros(3), np.zeros(3), np.zeros(3))
        below = np.flatnonzero(bounds < cap)
        for k in below[np.argsort(bounds[below], kind="stable")].tolist():
            if bounds[k] >= best:
                break  # sorted: no later pair can lower the minimum
            d, a, b, n = self.pair(k, tf)
            narrow += 1
            if d < best:
                best, arg, witness = d, k, (a, b, n)
        a, b, n = witness
        return np.array([best]), np.array([arg]), a[None], b[None], n[None], narrow

    def gradient(self, q: np.ndarray, pair: np.ndarray, p1, p2, normal) -> np.ndarray:
        """(T, dof) gradients nᵀ(J(p₂) − J(p₁)) of the minimising pairs (0 where pair = −1)."""
        out = np.zeros((len(pair), self.robot.dof))
        live = pair >= 0
        if not live.any():
            return out
        jac, origins = self.robot.joint_jacobians(q)
        k = pair[live]
        body_a = self.robot.shape_body[self.pair_a[k]]
        ja = point_jacobians(jac[body_a], origins[body_a], p1[live])
        grad = -np.einsum("ti,tij->tj", normal[live], ja)
        self_rows = self.is_self[k]
        if self_rows.any():
            body_b = self.robot.shape_body[self.pair_b[k[self_rows]]]
            jb = point_jacobians(jac[body_b], origins[body_b], p2[live][self_rows])
            grad[self_rows] += np.einsum("ti,tij->tj", normal[live][self_rows], jb)
        out[live] = grad
        return out

    # ------------------------------------------------------------------ batches
    def evaluate(
        self,
        q: np.ndarray,
        per_link: bool = False,
        cap: float = np.inf,
        broad_phase: bool = True,
        gradient: bool = False,
    ) -> Distances3D:
        """Signed distances (and gradients) of configurations q (B, dof) or (dof,) in rad."""
        q = self.robot.check_q(q)
        cap = _check_cap(cap)
        tf, bounds = self.placements_batch(q)
        rows = [
            self.scan(qi, per_link, cap, broad_phase, (tf[i], bounds[i])) for i, qi in enumerate(q)
        ]
        dist = np.array([r[0] for r in rows])
        pair = np.array([r[1] for r in rows])
        p1, p2, nrm = (np.array([r[i] for r in rows]) for i in (2, 3, 4))
        narrow = np.array([r[5] for r in rows], dtype=int)
        grad = None
        if gradient:
            grad = np.array([self.gradient(qi, *r[1:5]) for qi, r in zip(q, rows, strict=True)])
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

    def pair_distances(self, q: np.ndarray, cap: float = np.inf) -> tuple[np.ndarray, np.ndarray]:
        """(B, P) signed distance of every pair (``cap`` where the lower bound reaches it) and
        (B,) narrow-phase counts."""
        q = self.robot.check_q(q)
        cap = _check_cap(cap)
        out = np.full((len(q), self.n_pairs), cap)
        narrow = np.zeros(len(q), dtype=int)
        tf, bounds = self.placements_batch(q)
        for i in range(len(q)):
            for k in np.flatnonzero(bounds[i] < cap):
                out[i, k] = min(self.pair(k, tf[i])[0], cap)
                narrow[i] += 1
        return out, narrow


def _check_cap(cap) -> float:
    try:
        value = float(cap)
    except (TypeError, ValueError) as e:
        raise InputError(f"cap: expected a number (m) or inf, got {cap!r}") from e
    if np.isnan(value) or isinstance(cap, bool):
        raise InputError(f"cap: expected a number (m) or inf, got {cap!r}")
    return value


_CHECKERS: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def checker3d(scene: Scene3D, tolerance: float | None = None) -> Checker3D:
    """The cached :class:`Checker3D` of a scene (one per tolerance)."""
    per_scene = _CHECKERS.setdefault(scene, {})
    if tolerance not in per_scene:
        per_scene[tolerance] = Checker3D(scene, tolerance)
    return per_scene[tolerance]


def signed_distance3d(
    scene: Scene3D, q, per_link: bool = False, cap: float = np.inf, broad_phase: bool = True
) -> np.ndarray:
    """Signed distance (m) of configurations q (B, dof) or (dof,): (B,), or (B, L) per link.

    Positive when free, minus the penetration depth when overlapping (obstacles and enabled
    self-collision pairs); ``cap`` where every pair's lower bound reaches ``cap``.
    """
    return checker3d(scene).evaluate(q, per_link, cap, broad_phase).distance


def signed_distance3d_and_grad(
    scene: Scene3D, q, per_link: bool = False, cap: float = np.inf, broad_phase: bool = True
) -> tuple[np.ndarray, np.ndarray]:
    """Signed distance and its exact gradient: ((B,), (B, dof)) or ((B, L), (B, L, dof))."""
    res = checker3d(scene).evaluate(q, per_link, cap, broad_phase, gradient=True)
    return res.distance, res.gradient


class Coal3DModel:
    """Exact 3-D signed distance from coal as a :class:`~gdnplan.models.DistanceModel`."""

    name = "coal3d"

    def distance(self, scene: Scene3D, q: np.ndarray) -> np.ndarray:
        return signed_distance3d(scene, q)

    def distance_and_grad(
        self, scene: Scene3D, q: np.ndarray, per_link: bool = False, cap: float = np.inf
    ) -> tuple[np.ndarray, np.ndarray]:
        """Distances and gradients, overall or ``per_link`` ((B, L), (B, L, dof): the Ipopt
        transcription's one row per link); pairs whose bound reaches ``cap`` (m) are skipped
        and a link with none below it reports ``cap`` with a zero gradient."""
        return signed_distance3d_and_grad(scene, q, per_link=per_link, cap=cap)
