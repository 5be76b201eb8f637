"""Samples of the ``ur5e`` environment (the fetch robot, paper §V-C), which varies the robot too.

Each sample draws a gripper state (open, closed, holding), a storage layout and 1–3 random boxes
around it. Building a random fetch layout searches for free grasps (slow next to labelling a
sample), so each split draws its layouts from a fixed pool of ``UR5E_LAYOUTS`` fetch seeds

    layout_seed = FETCH_SEED_BASE + seed · 10⁶ + k,   k = 0 … UR5E_LAYOUTS − 1,

disjoint between splits and from the benchmark's seeds (< FETCH_SEED_BASE); the train split
also uses the canonical layout (fetch seed 0) for a ``CANONICAL_SHARE`` of its samples. The
obstacles are the fetch scene's for that gripper state (table, storage, and the stick unless
held) plus the boxes; when holding, the robot carries the layout's stick (length 0.15–0.30 m,
width 0.02–0.04 m). ``scene_seed`` is the fetch seed of the sample's layout. With
``near`` > 0, that fraction of the samples is concentrated near the task's contacts:

    q = clip(q_ref + ε, limits),  ε ~ N(0, σ² I),  log σ ~ U(log σ_min, log σ_max),

q_ref drawn from the layout's configurations of that gripper state (open/closed: q_home,
q_pregrasp, q_grasp; holding: q_grasp, q_lift, q_out) or from the joint-space segments of the
task through the entrance (open/closed: q_pregrasp → q_grasp; holding: q_lift → q_out, at a
uniform fraction s: q_ref = q_a + s (q_b − q_a)), where uniform samples rarely fall, and
(σ_min, σ_max) = NEAR_SIGMA: the log-uniform scale puts samples at every distance from the
contacts, down to the millimetres of the stick resting on its shelf (at 0.005 rad the tcp moves
≈ 3 mm).
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from ..distance import signed_distance_and_grad
from ..geometry import pad_polygons
from ..robot import Robot
from ..scene import Scene, clear_of_base, make_scene
from ..ur5e import GRIPPER_STATES, TABLE_V
from .dataset import SPLITS, Dataset

UR5E_LAYOUTS = 300  # fetch layouts per split
FETCH_SEED_BASE = 10_000  # first fetch seed of the dataset layouts (benchmarks use smaller)
CANONICAL_SHARE = 0.1  # fraction of ur5e train samples on the canonical layout (fetch seed 0)
NEAR_SIGMA = (0.005, 0.2)  # rad: range of the log-uniform spread of the near-contact samples
NEAR_REFS = {  # gripper state -> fetch configurations the near-contact samples spread around
    "open": ("q_home", "q_pregrasp", "q_grasp"),
    "closed": ("q_home", "q_pregrasp", "q_grasp"),
    "holding": ("q_grasp", "q_lift", "q_out"),
}
NEAR_SEGMENTS = {  # gripper state -> task segments (joint-space lines) through the entrance
    "open": (("q_pregrasp", "q_grasp"),),
    "closed": (("q_pregrasp", "q_grasp"),),
    "holding": (("q_lift", "q_out"),),
}


@lru_cache(maxsize=2048)
def _fetch_base(layout_seed: int, gripper: str) -> Scene:
    return make_scene("fetch", seed=layout_seed, gripper=gripper)


def random_boxes(rng: np.random.Generator, robot: Robot, k: int) -> list[np.ndarray]:
    """k random rectangles around the storage, clear of the robot's base (CCW (4, 2), m).

    Centre u ∈ [0.25, 1.4], v ∈ [TABLE_V, TABLE_V + 1], sides ∈ [0.04, 0.25], rotation
    θ ∈ [0, π/2); drawn again while within ``robot.base_radius`` of joint 1.
    """
    boxes: list[np.ndarray] = []
    while len(boxes) < k:
        c = np.array([rng.uniform(0.25, 1.4), rng.uniform(TABLE_V, TABLE_V + 1.0)])
        half = rng.uniform(0.02, 0.125, 2)
        t = rng.uniform(0, np.pi / 2)
        rot = np.array([[np.cos(t), -np.sin(t)], [np.sin(t), np.cos(t)]])
        box = c + (np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]]) * half) @ rot.T
        if clear_of_base(box, robot):
            boxes.append(box)
    return boxes


def ur5e_layout_seeds(seed: int) -> np.ndarray:
    """Fetch seeds of the layout pool of the split with ``seed`` (see the module docstring)."""
    return FETCH_SEED_BASE + seed * 10**6 + np.arange(UR5E_LAYOUTS, dtype=np.int64)


def near_reference(rng: np.random.Generator, info: dict, gripper: str) -> np.ndarray:
    """(3,) q_ref of a near-contact sample: one of the NEAR_REFS configurations or a point of a
    NEAR_SEGMENTS segment, uniformly over the union of both lists (module docstring)."""
    refs, segments = NEAR_REFS[gripper], NEAR_SEGMENTS[gripper]
    k = int(rng.integers(len(refs) + len(segments)))
    if k < len(refs):
        return info[refs[k]]
    a, b = (info[name] for name in segments[k - len(refs)])
    return a + rng.uniform() * (b - a)


def make_ur5e_shard(seed: int, start: int, n: int, near: float = 0.0) -> Dataset:
    """Samples ``start … start + n − 1`` of the ``ur5e`` split with ``seed``.

    Per sample (rng seeded by (seed, start)): gripper state uniform over GRIPPER_STATES, a
    layout from the split's pool (the canonical one with probability CANONICAL_SHARE except in
    the test split), 1–3 random boxes, q uniform within the limits or, with probability
    ``near``, near a task configuration (module docstring); labels from coal.
    """
    rng = np.random.default_rng([seed, start, 7])
    pool = ur5e_layout_seeds(seed)
    gripper = rng.integers(0, len(GRIPPER_STATES), n).astype(np.int8)
    layout = pool[rng.integers(0, len(pool), n)]
    if seed != SPLITS["test"][0]:
        layout[rng.random(n) < CANONICAL_SHARE] = 0
    is_near = rng.random(n) < near if near > 0 else np.zeros(n, bool)  # uniform: rng as before
    q = np.empty((n, 3))
    stick = np.zeros((n, 2))
    d, grad = np.empty(n), np.empty((n, 3))
    polys, nodes = [], []
    for i in range(n):
        base = _fetch_base(int(layout[i]), GRIPPER_STATES[gripper[i]])
        robot = base.robot
        if GRIPPER_STATES[gripper[i]] == "holding":
            stick[i] = robot.info["stick_length"], robot.info["stick_width"]
        obstacles = (*base.obstacles, *random_boxes(rng, robot, int(rng.integers(1, 4))))
        scene = Scene(robot, obstacles, name="ur5e")
        q[i] = robot.sample(1, seed=[seed, start + i])[0]
        if is_near[i]:
            ref = near_reference(rng, base.info, GRIPPER_STATES[gripper[i]])
            sigma = np.exp(rng.uniform(*np.log(NEAR_SIGMA)))
            q[i] = np.clip(ref + rng.normal(0.0, sigma, 3), robot.lower, robot.upper)
        di, gi = signed_distance_and_grad(scene, q[i][None])
        d[i], grad[i] = di[0], gi[0]
        polys.append(list(obstacles))
        nodes.append(robot.node_positions(q[i][None])[0])
    obstacles_arr, sizes = pad_polygons(polys)
    n_nodes = max(len(x) for x in nodes)
    padded = np.zeros((n, n_nodes, 2), np.float32)
    for i, x in enumerate(nodes):
        padded[i, : len(x)] = x
    return Dataset("ur5e", q, padded, obstacles_arr, sizes, d, grad, layout, gripper, stick)
