"""Ground truth: exact signed collision distance f_cd with coal, and its exact gradient.

The paper's collision distance (§IV-D) between the robot R(q) and obstacles O_1 … O_n is

    f_cd(q) = min_i dist(R(q), O_i)          when R(q) touches no obstacle,
            = −max_i depth(R(q), O_i)        otherwise (penetration depth),

which is the minimum of coal's signed distances over all (link polygon, convex obstacle part)
pairs. Polygons become tall convex prisms, ±H in z with H = :func:`prism_half_height` of the
scene, so the penetration solver cannot escape through z: two prisms of one height overlap by
2H in z, while the in-plane depth of a link polygon A and an obstacle part B is at most
min_n (w_A(n) + w_B(n)) / 2 ≤ r_A + r_B (w the widths along n, r the bounding-circle radii), so

    H = max(``MIN_PRISM_HALF_HEIGHT``, ``PRISM_SAFETY`` · (max_A r_A + max_B r_B))

makes the z escape cost 2H at least 2 · ``PRISM_SAFETY`` times any in-plane depth of the
scene. Every shipped scene keeps H = 1 m (its prisms as before); obstacles up to
:func:`gdnplan.scene.coordinate_bound` make H a few hundred metres. Apart
shapes do not depend on H (GJK, unchanged values); overlapping ones go to EPA, whose tolerance
``EPA_TOLERANCE`` is tight enough that tall prisms keep the depth exact to ~1e-15 (coal's
default 1e-6 lost 1e-3 relative at H = 3 km, tests/test_distance_depth.py). Where EPA fails at
that tolerance (it returns −DBL_MAX), the pair is recomputed with coal's default request, and
if that fails too its bounding circles' lower bound is used (:meth:`CoalChecker._pair`).

For the winning pair coal returns witness points p₁ (on the link) and p₂ (on the obstacle)
and the unit normal n from shape 1 to shape 2 with d = n · (p₂ − p₁). As only p₁ moves,

    ∂d/∂q_j = −n · ∂p₁/∂q_j = −n · s_j ẑ × (p₁ − o_j(q))   for every joint j upstream of the link,

exact wherever the witness pair is unique. A broad phase on bounding circles skips pairs whose
lower bound |c_k − c_p| − r_k − r_p cannot beat the best distance found so far.
"""

from __future__ import annotations

import logging
import math
import os
import weakref
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass
from multiprocessing import get_context

import coal
import numpy as np

from .flags import check_flag
from .robot import cross_z
from .scene import Scene, check_scene

MIN_PRISM_HALF_HEIGHT = 1.0  # m: the prisms' half-height in small scenes (all shipped ones)
PRISM_SAFETY = 1.0  # half-height / (largest link radius + largest part radius)
EPA_TOLERANCE = 1e-9  # coal's EPA stopping tolerance (its default 1e-6 is too loose, above)
PARALLEL_MIN_BATCH = 2000  # batches at least this large are split over all cores

log = logging.getLogger(__name__)


def prism_half_height(scene: Scene) -> float:
    """H (m) of the module docstring: the prisms' half-height for this scene's shapes."""
    radii = [_circle(p.vertices0)[1] for p in scene.robot.polygons]
    radii_parts = [_circle(p)[1] for p in scene.obstacle_parts] or [0.0]
    return max(MIN_PRISM_HALF_HEIGHT, PRISM_SAFETY * (max(radii) + max(radii_parts)))


def _prism(poly: np.ndarray, half_height: float) -> coal.ConvexBase:
    """Convex prism over a convex polygon (m, 2), ±half_height (m) in z."""
    top = np.c_[poly, np.full(len(poly), half_height)]
    bottom = np.c_[poly, np.full(len(poly), -half_height)]
    points = coal.StdVec_Vec3s()
    for p in np.vstack([top, bottom]):
        points.append(p)
    return coal.ConvexBase.convexHull(points, False, "")


def _circle(poly: np.ndarray) -> tuple[np.ndarray, float]:
    """Bounding circle (centre at the vertex mean, radius to the farthest vertex)."""
    c = poly.mean(0)
    return c, float(np.max(np.linalg.norm(poly - c, axis=1)))


@dataclass
class Witness:
    """The closest (or deepest) pair of one configuration: distance, points, normal, link."""

    distance: np.ndarray  # (B,) or (B, L)
    point: np.ndarray  # (..., 2) witness point on the robot
    normal: np.ndarray  # (..., 2) unit normal, robot -> obstacle
    link: np.ndarray  # (...,) link polygon index


class CoalChecker:
    """Coal shapes and distance functors of one scene, reused across calls."""

    def __init__(self, scene: Scene):
        check_scene(scene, use="gdnplan.arm3d.Checker3D")
        robot = scene.robot
        self.robot = robot
        self.half_height = height = prism_half_height(scene)
        self.link_shapes = [_prism(p.vertices0, height) for p in robot.polygons]
        self.link_body = np.array([p.body for p in robot.polygons])
        circles = [_circle(p.vertices0) for p in robot.polygons]
        self.link_center0 = np.array([c for c, _ in circles]).reshape(-1, 2)
        self.link_radius = np.array([r for _, r in circles])
        parts = scene.obstacle_parts
        self.part_shapes = [_prism(p, height) for p in parts]
        circles = [_circle(p) for p in parts]
        self.part_center = np.array([c for c, _ in circles]).reshape(-1, 2)
        self.part_radius = np.array([r for _, r in circles])
        self.identity = coal.Transform3s()
        self.request = coal.DistanceRequest()
        self.request.enable_signed_distance = True
        self.request.epa_tolerance = EPA_TOLERANCE
        self.fallback = coal.DistanceRequest()  # coal's defaults: retried when EPA fails
        self.fallback.enable_signed_distance = True
        self.result = coal.DistanceResult()
        self.functors = [
            [coal.ComputeDistance(ls, ps) for ps in self.part_shapes] for ls in self.link_shapes
        ]

    # ------------------------------------------------------------------ broad phase
    def lower_bounds(self, poses: np.ndarray) -> np.ndarray:
        """(B, L, P) lower bounds on each pair's distance from bounding circles."""
        body_pose = poses[:, self.link_body]  # (B, L, 3)
        c, s = np.cos(body_pose[..., 2]), np.sin(body_pose[..., 2])
        x0, y0 = self.link_center0[:, 0], self.link_center0[:, 1]
        centers = np.stack([c * x0 - s * y0, s * x0 + c * y0], -1) + body_pose[..., :2]
        gap = np.linalg.norm(centers[:, :, None] - self.part_center[None, None], axis=-1)
        return gap - self.link_radius[None, :, None] - self.part_radius[None, None, :]

    # ------------------------------------------------------------------ narrow phase
    def _pair(
        self, link: int, part: int, tf: coal.Transform3s
    ) -> tuple[float, np.ndarray, np.ndarray]:
        """Signed distance (m), witness point on the link (2,) and unit normal (2,) of a pair.

        coal's EPA sometimes fails at ``EPA_TOLERANCE`` (it returns −DBL_MAX): a distance below
        −(r_link + r_part), deeper than the bounding circles allow, is recomputed with coal's
        default request, and if that fails too the bounding circles' bound is used."""
        res = self.result
        deepest = -(self.link_radius[link] + self.part_radius[part])
        for request in (self.request, self.fallback):
            res.clear()
            self.functors[link][part](tf, self.identity, request, res)
            d = res.min_distance
            if math.isfinite(d) and d >= deepest:
                return d, res.getNearestPoint1()[:2].copy(), res.normal[:2].copy()
        return self._circle_bound(link, part, tf)

    def _circle_bound(
        self, link: int, part: int, tf: coal.Transform3s
    ) -> tuple[float, np.ndarray, np.ndarray]:
        """The bounding circles' lower bound |c_l − c_p| − r_l − r_p of a pair (coal failed
        twice), its witness on the link's circle and the normal along the centres."""
        log.warning("coal failed on link %d and obstacle part %d; using their circles", link, part)
        center = tf.transform(np.r_[self.link_center0[link], 0.0])[:2]
        gap = self.part_center[part] - center
        n = gap / max(float(np.linalg.norm(gap)), 1e-12)
        d = float(np.linalg.norm(gap)) - self.link_radius[link] - self.part_radius[part]
        return d, center + self.link_radius[link] * n, n

    def _transforms(self, pose: np.ndarray) -> list[coal.Transform3s]:
        """Coal placements of every link polygon for one configuration's body poses (dof+1, 3)."""
        out = []
        for body in self.link_body:
            x, y, th = pose[body]
            c, s = np.cos(th), np.sin(th)
            rot = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
            out.append(coal.Transform3s(rot, np.array([x, y, 0.0])))
        return out

    def closest(self, q: np.ndarray, per_link: bool, cap: float = np.inf) -> Witness:
        """Signed distance witness for each configuration (or each configuration and link).

        Pairs whose lower bound exceeds ``cap`` are never evaluated; a link with no pair
        below ``cap`` reports ``cap`` with a zero normal (zero gradient).
        """
        n_links = len(self.link_shapes)
        poses = self.robot.body_poses(q)
        bounds = self.lower_bounds(poses)
        shape = (len(q), n_links) if per_link else (len(q),)
        dist = np.full(shape, cap, dtype=float)
        point = np.zeros((*shape, 2))
        normal = np.zeros((*shape, 2))
        link = (
            np.zeros(shape, dtype=int)
            if not per_link
            else np.broadcast_to(np.arange(n_links), shape).copy()
        )
        for b in range(len(q)):
            tfs = self._transforms(poses[b])
            if per_link:
                for k in range(n_links):
                    self._scan(bounds[b, k][None], [k], tfs, dist, point, normal, None, (b, k))
            else:
                self._scan(bounds[b], range(n_links), tfs, dist, point, normal, link, (b,))
        return Witness(dist, point, normal, link)

    def _scan(self, bounds, links, tfs, dist, point, normal, link, idx) -> None:
        """Evaluate pairs in order of their lower bound until none can beat the best."""
        links = list(links)
        flat = bounds.ravel()
        for f in np.argsort(flat):
            if flat[f] >= dist[idx]:
                break
            k, p = links[f // bounds.shape[1]], f % bounds.shape[1]
            d, p1, n = self._pair(k, p, tfs[k])
            if d < dist[idx]:
                dist[idx], point[idx], normal[idx] = d, p1, n
                if link is not None:
                    link[idx] = k


_CHECKERS: weakref.WeakKeyDictionary[Scene, CoalChecker] = weakref.WeakKeyDictionary()


def checker(scene: Scene) -> CoalChecker:
    """The cached :class:`CoalChecker` of a scene."""
    check_scene(scene, use="gdnplan.arm3d.checker3d")
    if scene not in _CHECKERS:
        _CHECKERS[scene] = CoalChecker(scene)
    return _CHECKERS[scene]


def witness_gradient(scene: Scene, q: np.ndarray, w: Witness) -> np.ndarray:
    """∂d/∂q = −n · Σ_j s_j ẑ × (p₁ − o_j(q)) over joints upstream of the witness link.

    Shapes follow ``w``: (B, dof) for the overall minimum, (B, L, dof) per link.
    """
    robot = scene.robot
    joints = robot.chain.joint_positions(q)  # (B, dof, 2)
    extra = w.point.ndim - 2  # 0 overall, 1 per link
    joints = joints.reshape(len(q), *([1] * extra), robot.dof, 2)
    lever = w.point[..., None, :] - joints  # (..., dof, 2)
    velocity = cross_z(lever) * robot.chain.joint_signs[:, None]
    body = np.array([p.body for p in robot.polygons])[w.link]
    upstream = body[..., None] > np.arange(robot.dof)
    return -np.einsum("...i,...ji->...j", w.normal, velocity) * upstream


_FORKED_SCENE: Scene | None = None  # the scene forked workers read (set just before forking)


def _closest_in_worker(q: np.ndarray, per_link: bool) -> Witness:
    return checker(_FORKED_SCENE).closest(q, per_link)


def closest(scene: Scene, q: np.ndarray, per_link: bool = False) -> Witness:
    """Witnesses of a batch, split over all cores (forked workers) for large batches."""
    per_link = check_flag(per_link, "per_link")
    workers = min(os.cpu_count() or 1, len(q) // (PARALLEL_MIN_BATCH // 2))
    if workers < 2 or get_context().get_start_method() != "fork":
        return checker(scene).closest(q, per_link)
    global _FORKED_SCENE
    _FORKED_SCENE = scene
    chunks = np.array_split(q, workers)
    with ProcessPoolExecutor(workers, mp_context=get_context("fork")) as pool:
        parts = list(pool.map(_closest_in_worker, chunks, [per_link] * workers))
    _FORKED_SCENE = None
    return Witness(
        *(
            np.concatenate([getattr(p, f) for p in parts])
            for f in ("distance", "point", "normal", "link")
        )
    )


def signed_distance(scene: Scene, q: np.ndarray, per_link: bool = False) -> np.ndarray:
    """Exact signed collision distance f_cd (m): (B,), or (B, n_links) with ``per_link``.

    Positive when free, negative (minus the penetration depth) when overlapping. Batches of
    ``PARALLEL_MIN_BATCH`` or more are split over the machine's cores.
    """
    check_scene(scene, use="gdnplan.arm3d.signed_distance3d")
    q = scene.robot.check_q(q)
    return closest(scene, q, per_link).distance


def signed_distance_and_grad(
    scene: Scene, q: np.ndarray, per_link: bool = False
) -> tuple[np.ndarray, np.ndarray]:
    """Signed distance and its exact gradient: ((B,), (B, dof)) or ((B, L), (B, L, dof))."""
    check_scene(scene, use="gdnplan.arm3d.signed_distance3d_and_grad")
    q = scene.robot.check_q(q)
    w = closest(scene, q, per_link)
    return w.distance, witness_gradient(scene, q, w)


def witness(scene: Scene, q: np.ndarray) -> tuple[float, np.ndarray, np.ndarray]:
    """Distance and the witness segment (p_robot, p_obstacle) of one configuration, for plots."""
    check_scene(scene, use="gdnplan.arm3d.signed_distance3d")
    q = scene.robot.check_q(q)
    w = checker(scene).closest(q[:1], per_link=False)
    d, p1, n = float(w.distance[0]), w.point[0], w.normal[0]
    return d, p1, p1 + d * n
