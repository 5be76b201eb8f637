"""The pair table of a 3-D scene and coal's narrow phase of one pair.

The pairs of a :class:`~gdnplan.arm3d.scene3d.Scene3D` are every (robot shape, obstacle) and
every enabled self-collision pair (robot shape, robot shape) of
:attr:`~gdnplan.arm3d.robot3d.Robot3D.self_pairs`. For pair k between shape 1 and shape 2
:meth:`PairTable.pair` returns the signed distance d_k (the distance when apart, minus the
penetration depth when overlapping), witness points p₁ (on shape 1, the robot's), p₂ (on
shape 2) and the unit normal n from shape 1 to shape 2, with p₂ − p₁ = d_k n.

Contact-only pairs (:mod:`gdnplan.arm3d.pairs`): :attr:`PairTable.contact_only` marks the self
pairs that must only stay out of contact. :meth:`PairTable.offsets` gives the per-pair offset
o_k (m) added to d_k before it is compared with a margin M: o_k = M on contact-only pairs, 0
elsewhere, so

    min_k (d_k + o_k) ≥ M   ⟺   d_k ≥ M on obstacle and ordinary self pairs, d_k ≥ 0 on
                                 contact-only pairs.

o_k is a constant: it shifts a pair's value but not how fast it can change along a path (the
certificate's motion bounds hold unchanged) nor its gradient. An offset of +inf leaves the
contact-only pairs out; 0 gives the true signed distances.

Broad-phase bounds: every shape has a bounding sphere (centre c, radius r, from coal's local
AABB), so d_k ≥ b_k = |c₁ − c₂| − r₁ − r₂ (:meth:`PairTable.placements_batch`).

coal's accuracy: GJK runs on the shapes' cores (a sphere's centre, a capsule's segment, a shape
less its swept-sphere radius) and subtracts the swept radii ρ_k = ρ₁ + ρ₂ afterwards, so its
relative tolerance τ bounds d̂_k − d_k ≤ τ (1 + |d̂_k| + ρ_k) (:mod:`gdnplan.ccd`), not
τ (1 + |d̂_k|): :attr:`PairTable.swept_max` = max_k ρ_k is what the certificates add to their
slack (:func:`gdnplan.ccd.proven_distance`).

coal conventions handled here:

* an obstacle that is a coal ``OcTree`` (a point cloud as voxels): coal returns its witness
  points and normal in the order (octree, shape) whichever order the shapes are given in, so
  p₁ lies on the octree and n points from it to the robot; such pairs are swapped back
  (p₁ ↔ p₂, n → −n) so every pair keeps the convention above;
* coal's EPA sometimes fails on curved shapes at tight tolerances (it returns −DBL_MAX): such a
  pair is recomputed with coal's default request, and if that fails too it reports its
  bounding-sphere bound b_k (a lower bound, with a warning on the ``gdnplan.arm3d`` logger).
"""

from __future__ import annotations

import logging

import coal
import numpy as np

from ..errors import InputError
from ..limits import is_number, shown
from .fk3d import shape_placements_batch
from .scene3d import Scene3D

log = logging.getLogger("gdnplan.arm3d")


class PairTable:
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
        self.contact_only = np.r_[np.zeros(len(obs), bool), robot.self_contact_only].astype(bool)
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
        obs_swept = [swept_radius(o.shape) for o in scene.obstacles]
        shape_swept = np.array([swept_radius(s.shape) for s in robot.shapes])
        swept = (
            shape_swept[self.pair_a]
            + np.r_[np.asarray(obs_swept, float)[obs[:, 1]], shape_swept[self_b]]
        )
        self.swept_max = float(np.max(swept, initial=0.0))  # m, the largest ρ_k (module doc)
        self.functors = [
            coal.ComputeDistance(
                robot.shapes[a].shape,
                robot.shapes[b].shape if s else scene.obstacles[b].shape,
            )
            for a, b, s in zip(self.pair_a, self.pair_b, self.is_self, strict=True)
        ]
        self.request = coal.DistanceRequest()
        self.request.enable_signed_distance = True
        tolerance = check_tolerance(tolerance)
        if tolerance is not None:
            self.request.gjk_tolerance = tolerance
            self.request.epa_tolerance = tolerance
        self.fallback = coal.DistanceRequest()  # coal's defaults: retried when EPA fails
        self.fallback.enable_signed_distance = True
        self.fallbacks = 0  # pairs retried with the fallback request
        self.result = coal.DistanceResult()
        # obstacle pairs whose coal witnesses come in the order (obstacle, robot shape)
        self.swapped = np.r_[
            [isinstance(scene.obstacles[b].shape, coal.OcTree) for b in obs[:, 1]],
            np.zeros(len(robot.self_pairs), bool),
        ].astype(bool)

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

    def offsets(self, contact_offset: float) -> np.ndarray:
        """(P,) offsets o_k (m): ``contact_offset`` on contact-only pairs, 0 on the others
        (module docstring; pass the margin M to compare min_k (d_k + o_k) with M)."""
        value = check_offset(contact_offset)
        return np.where(self.contact_only, value, 0.0)

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

    def pair_poses(self, k: int, tf: np.ndarray) -> tuple[coal.Transform3s, coal.Transform3s]:
        """coal placements of pair k's two shapes, given the robot shapes' placements ``tf``
        (S, 4, 4): shape a's, and shape b's (another robot shape's, or the obstacle's pose)."""
        a, b = self.pair_a[k], self.pair_b[k]
        tf_a = coal.Transform3s(tf[a, :3, :3], tf[a, :3, 3])
        if self.is_self[k]:
            return tf_a, coal.Transform3s(tf[b, :3, :3], tf[b, :3, 3])
        return tf_a, self.scene.obstacles[b].pose

    def pair(self, k: int, tf: np.ndarray) -> tuple[float, np.ndarray, np.ndarray, np.ndarray]:
        """Signed distance (m), witness points p₁, p₂ (3,) and normal n (3,) of pair k."""
        tf_a, tf_b = self.pair_poses(k, tf)
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
        if self.swapped[k]:  # coal's octree order (module doc)
            return d, p2, p1, -np.array(res.normal)
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

    def pair_distances(self, q: np.ndarray, cap: float = np.inf) -> tuple[np.ndarray, np.ndarray]:
        """(B, P) signed distance of every pair (``cap`` where the lower bound reaches it) and
        (B,) narrow-phase counts."""
        q = self.robot.check_q(q)
        cap = check_cap(cap)
        out = np.full((len(q), self.n_pairs), cap)
        narrow = np.zeros(len(q), dtype=int)
        tf, bounds = self.placements_batch(q)
        for i in range(len(q)):
            for k in np.flatnonzero(bounds[i] < cap):
                out[i, k] = min(self.pair(k, tf[i])[0], cap)
                narrow[i] += 1
        return out, narrow


def swept_radius(shape) -> float:
    """The radius (m) coal sweeps around ``shape``'s core after GJK: a sphere's or a capsule's
    radius, plus the shape's own swept-sphere radius (0 unless set); 0 for an octree."""
    core = float(shape.radius) if isinstance(shape, (coal.Sphere, coal.Capsule)) else 0.0
    own = shape.getSweptSphereRadius() if hasattr(shape, "getSweptSphereRadius") else 0.0
    return core + float(own)


MAX_TOLERANCE = 1e-2  # GJK/EPA tolerance: beyond it a "distance" is off by centimetres


def check_tolerance(tolerance) -> float | None:
    """``tolerance`` (None: coal's default) as a float in (0, :data:`MAX_TOLERANCE`], else
    InputError (a negative or NaN tolerance made every distance 0, a string raised Boost's
    ArgumentError)."""
    if tolerance is None:
        return None
    if not (is_number(tolerance) and 0 < tolerance <= MAX_TOLERANCE):
        raise InputError(
            f"tolerance: expected None or a number in (0, {MAX_TOLERANCE:g}] (coal's GJK/EPA "
            f"tolerance; default 1e-6), got {shown(tolerance)}"
        )
    return float(tolerance)


def check_cap(cap) -> float:
    """``cap`` as a float (m; inf allowed), InputError when it is not a number or NaN."""
    try:
        value = float(cap)
    except (TypeError, ValueError, OverflowError) as e:  # OverflowError: an int past 1e308
        raise InputError(f"cap: expected a number (m) or inf, got {shown(cap)}") from e
    if np.isnan(value) or isinstance(cap, bool):
        raise InputError(f"cap: expected a number (m) or inf, got {shown(cap)}")
    return value


def check_offset(contact_offset) -> float:
    """``contact_offset`` as a float (m; +inf allowed), InputError for NaN, −inf or a non-number."""
    bad = InputError(f"contact_offset: expected a number (m) or inf, got {shown(contact_offset)}")
    if isinstance(contact_offset, bool):
        raise bad
    try:
        value = float(contact_offset)
    except (TypeError, ValueError, OverflowError) as e:
        raise bad from e
    if np.isnan(value) or value == -np.inf:
        raise bad
    return value


__all__ = [
    "MAX_TOLERANCE",
    "PairTable",
    "check_cap",
    "check_offset",
    "check_tolerance",
    "swept_radius",
]
