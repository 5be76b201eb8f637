"""Samples of the 3-D environments, labelled by coal: a UR5e among 20 random boxes.

Environment ``ur5e_boxes``: scenes of ``N_BOXES`` axis-aligned boxes
(:func:`gdnplan.arm3d.random_boxes`: centres in the upper half of the arm's reach, sides
5–20 cm), ``SCENE_SAMPLES`` configurations per scene. Scene s of the split with ``seed`` has

    scene_seed = seed · 10⁸ + s,

and the configurations of the shard starting at sample ``start`` come from an rng seeded by
(seed, start), so a shard is a pure function of (env, seed, start, n, near): the local pool and
Ray write the same bytes. A configuration is uniform within the joint limits or, with
probability ``near``, uniform conditioned on |f| < ``BOUNDARY_BAND`` (rejection among uniform
candidates labelled by coal): where the collision label is decided.

Environment ``ur5e_cloud``: obstacles known only as a point cloud. A scene samples
``CLOUD_POINTS`` points uniformly on the faces of ``CLOUD_BOXES`` random boxes (the same box
distribution), each moved by Gaussian sensor noise of ``CLOUD_NOISE`` m; the cloud's geometry is
the union of balls of radius ``POINT_RADIUS`` around its points (coal spheres), which the
labels and a certificate use (not coal's octree, whose normals have the opposite sign
convention in Checker3D's gradient).

Environment ``ur5e_storage``: the fetch's table and a random storage at a random placement,
the UR5e with its fingers open (the stick an obstacle) or holding the stick, one variant per
scene (:mod:`gdnplan.data.samples_storage3d`, which also names its shard arrays).

Labels: f(q) = the robot–obstacle signed distance (m), the minimum of coal's signed distances
over the (link shape, box) pairs — self-collision is not learned (GraphDistNet-3D's model adds
the exact self distance beside it) — and its exact gradient ∂f/∂q (m/rad)
(:class:`gdnplan.arm3d.Checker3D`, coal's default tolerance).

Shard arrays (n samples, S scenes):

============ =================== ==========================================
q            (n, dof) float64    joint angles (rad)
d            (n,) float64        robot–obstacle signed distance (m)
grad         (n, dof) float64    ∂d/∂q (m/rad)
scene        (n,) int32          the sample's row in the shard's scene table
scene_seed   (S,) int64          seeds of the shard's scenes
box_center   (S, N_BOXES, 3)     box centres (m)
box_size     (S, N_BOXES, 3)     full box sides (m) (``ur5e_boxes``)
points       (S, CLOUD_POINTS, 3) the scenes' point clouds (m) (``ur5e_cloud``)
============ =================== ==========================================
"""

from __future__ import annotations

from functools import cache

import numpy as np

from ..arm3d import (
    Checker3D,
    Robot3D,
    Scene3D,
    box_obstacle,
    load_robot3d,
    random_boxes,
    sphere_obstacle,
)
from ..errors import InputError, UnknownNameError
from .samples_storage3d import storage_scenes
from .shard_folder import SCENE_SEED_STRIDE, check_data_seed

ENVS3D = {"ur5e_boxes": "ur5e", "ur5e_cloud": "ur5e", "ur5e_storage": "ur5e"}  # env -> robot
N_BOXES = 20
CLOUD_BOXES = 10  # boxes whose surfaces a cloud samples
CLOUD_POINTS = 400  # points per cloud
CLOUD_NOISE = 0.002  # m: standard deviation of the sensor noise
POINT_RADIUS = 0.01  # m: radius of the ball around every cloud point
SCENE_SAMPLES = 50  # configurations per scene
BOUNDARY_BAND = 0.03  # m: near-boundary samples have |f| below this


@cache
def obstacle_robot(name: str) -> Robot3D:
    """The built-in robot ``name`` without self-collision pairs (labels are robot–obstacle)."""
    r = load_robot3d(name)
    return Robot3D(r.name, r.model, r.shapes, np.zeros((0, 2), int), {}, r.info)


def env_robot3d(env: str) -> Robot3D:
    """The robot of a 3-D environment (with its self-collision pairs)."""
    if env not in ENVS3D:
        raise UnknownNameError(
            f"env: unknown 3-D environment {env!r}; choose one of {list(ENVS3D)}"
        )
    return load_robot3d(ENVS3D[env])


def scene_boxes(env: str, scene_seed: int) -> tuple[np.ndarray, np.ndarray]:
    """Centres and sizes (N_BOXES, 3) of scene ``scene_seed`` (m)."""
    return _boxes(env, scene_seed, N_BOXES)


def _boxes(env: str, scene_seed: int, n: int) -> tuple[np.ndarray, np.ndarray]:
    scene = random_boxes(env_robot3d(env), n, seed=int(scene_seed))
    centers = np.array([o.pose.getTranslation() for o in scene.obstacles])
    sizes = np.array([2 * np.asarray(o.shape.halfSide) for o in scene.obstacles])
    return centers, sizes


def boxes_scene(robot: Robot3D, centers: np.ndarray, sizes: np.ndarray) -> Scene3D:
    """The Scene3D of axis-aligned boxes (centres and full sides (M, 3), m) around ``robot``."""
    return Scene3D(
        robot,
        [
            box_obstacle(s, c, name=f"box{i}")
            for i, (c, s) in enumerate(zip(centers, sizes, strict=True))
        ],
    )


def scene_cloud(env: str, scene_seed: int) -> np.ndarray:
    """(CLOUD_POINTS, 3) points of cloud scene ``scene_seed`` (m): uniform on the faces of
    CLOUD_BOXES random boxes (a face chosen with probability ∝ its area), plus noise."""
    centers, sizes = _boxes(env, scene_seed, CLOUD_BOXES)
    rng = np.random.default_rng([scene_seed, 5])
    sides = np.array([[s[1] * s[2], s[0] * s[2], s[0] * s[1]] for s in sizes])  # face areas
    area = np.repeat(sides, 2, 1).ravel()  # (M · 6) faces: ±x, ±y, ±z of every box
    face = rng.choice(len(area), CLOUD_POINTS, p=area / area.sum())
    box, axis, sign = face // 6, (face % 6) // 2, np.where(face % 2, 1.0, -1.0)
    u = rng.uniform(-0.5, 0.5, (CLOUD_POINTS, 3))
    u[np.arange(CLOUD_POINTS), axis] = 0.5 * sign
    return centers[box] + u * sizes[box] + rng.normal(0.0, CLOUD_NOISE, (CLOUD_POINTS, 3))


def cloud_scene(robot: Robot3D, points: np.ndarray) -> Scene3D:
    """The Scene3D of a cloud's geometry: balls of POINT_RADIUS around ``points`` (k, 3)."""
    return Scene3D(
        robot, [sphere_obstacle(POINT_RADIUS, p, name=f"point{i}") for i, p in enumerate(points)]
    )


def _near(checker: Checker3D, robot: Robot3D, k: int, rng: np.random.Generator) -> np.ndarray:
    """(k, dof) configurations uniform conditioned on |f| < BOUNDARY_BAND (rejection)."""
    kept, found = [np.empty((0, robot.dof))], 0
    for _ in range(1000):
        if found >= k:
            return np.concatenate(kept)[:k]
        cand = robot.random_configurations(max(8 * k, 32), rng)
        inside = cand[np.abs(checker.evaluate(cand, cap=BOUNDARY_BAND).distance) < BOUNDARY_BAND]
        kept.append(inside)
        found += len(inside)
    raise InputError(f"near: no configurations within {BOUNDARY_BAND} m of contact")


def make_shard3d(env: str, seed: int, start: int, n: int, near: float = 0.0) -> dict:
    """The arrays (module docstring) of samples ``start … start + n − 1`` of the split of
    ``env`` with ``seed``; ``start`` must be a multiple of SCENE_SAMPLES."""
    check_data_seed(seed)
    if start % SCENE_SAMPLES:
        raise InputError(f"start: expected a multiple of {SCENE_SAMPLES}, got {start}")
    robot = env_robot3d(env)
    labeller = obstacle_robot(robot.name)
    rng = np.random.default_rng([seed, start, 3])
    first = start // SCENE_SAMPLES
    n_scenes = -(-n // SCENE_SAMPLES)
    seeds = seed * SCENE_SEED_STRIDE + first + np.arange(n_scenes, dtype=np.int64)
    cloud = env == "ur5e_cloud"
    if env == "ur5e_storage":
        geometry, scenes = storage_scenes(seeds)
    elif cloud:
        geometry = {"points": np.array([scene_cloud(env, s) for s in seeds])}
        scenes = [cloud_scene(labeller, p) for p in geometry["points"]]
    else:
        centers, sizes = (
            np.array(x) for x in zip(*(scene_boxes(env, s) for s in seeds), strict=True)
        )
        geometry = {"box_center": centers, "box_size": sizes}
        scenes = [boxes_scene(labeller, c, z) for c, z in zip(centers, sizes, strict=True)]
    q, d, grad = np.empty((n, robot.dof)), np.empty(n), np.empty((n, robot.dof))
    scene = np.arange(n, dtype=np.int32) // SCENE_SAMPLES
    for s in range(n_scenes):
        rows = np.flatnonzero(scene == s)
        checker = Checker3D(scenes[s])  # the robot of the scene: same joints and limits
        qs = robot.random_configurations(len(rows), rng)
        is_near = rng.random(len(rows)) < near if near > 0 else np.zeros(len(rows), bool)
        if is_near.any():
            qs[is_near] = _near(checker, robot, int(is_near.sum()), rng)
        res = checker.evaluate(qs, gradient=True)
        q[rows], d[rows], grad[rows] = qs, res.distance, res.gradient
    return {
        "env": np.array(env),
        "q": q,
        "d": d,
        "grad": grad,
        "scene": scene,
        "scene_seed": seeds,
        **geometry,
    }
