"""Shards of a split: samples ``start … start + n − 1`` of an environment with a seed.

A sample is a configuration q drawn uniformly within the joint limits, the obstacle polygons of
its scene and the coal labels: the signed distance f_cd(q) (m) and its gradient ∂f/∂q (m/rad).
Fixed environments (a, c) share one scene; random environments (b, d, e) draw a new obstacle
set per sample with ``make_scene(env, seed=scene_seed)``, where

    scene_seed = seed · 10⁸ + index     (index = position of the sample in the split),

so a split is a pure function of (env, seed, n) and train (seed 0) and test (seed 1) never
share a scene. ``ur5e`` samples: :mod:`.ur5e_samples`.

For the environments a–e, ``near`` > 0 concentrates that fraction of the samples at the
collision boundary (beyond the paper, for AUC and gradients where they matter): a
near-boundary sample is q uniform within the limits conditioned on |f(q)| < ``BOUNDARY_BAND``,
drawn by rejection (uniform candidates labelled by coal, the first ones inside the band kept).

A split is drawn in blocks of ``SHARD_SIZE`` samples: block b is ``make_shard(env, seed,
b · SHARD_SIZE, SHARD_SIZE)``, the shard ``gdnplan generate`` writes as ``shard_<b>.npz``.
:func:`split_samples` is the one routine that makes any range of a split from those blocks,
for :func:`gdnplan.data.generate` (its shards) and for :func:`gdnplan.metrics.test_set`
(without ``data/``), so both give the same samples.
"""

from __future__ import annotations

import numpy as np

from ..distance import signed_distance, signed_distance_and_grad
from ..errors import InputError
from ..geometry import pad_polygons
from ..scene import Scene, make_scene
from .dataset import Dataset, concat
from .shard_folder import SCENE_SEED_STRIDE, check_data_seed
from .ur5e_samples import make_ur5e_shard

RANDOM_ENVS = ("b", "d", "e")
SHARD_SIZE = 2500  # samples per block of a split (one shard of gdnplan generate)
BOUNDARY_BAND = 0.03  # m: near-boundary samples of a–e have |f| below this


def near_boundary(scene: Scene, k: int, rng: np.random.Generator) -> np.ndarray:
    """(k, dof) configurations uniform within the limits conditioned on |f| < BOUNDARY_BAND
    (rejection sampling in batches of uniform candidates labelled by coal)."""
    robot = scene.robot
    batch = min(4096, max(256, 40 * k))
    kept = [np.empty((0, robot.dof))]
    found = 0
    for _ in range(10_000):
        if found >= k:
            return np.concatenate(kept)[:k]
        candidates = robot.sample(batch, seed=rng.integers(2**63))
        inside = candidates[np.abs(signed_distance(scene, candidates)) < BOUNDARY_BAND]
        kept.append(inside)
        found += len(inside)
    raise InputError(f"near: no configurations within {BOUNDARY_BAND} m of contact in {scene.name}")


def make_shard(env: str, seed: int, start: int, n: int, near: float = 0.0) -> Dataset:
    """Samples ``start … start + n − 1`` of the split of ``env`` with ``seed`` (``near``:
    fraction of near-contact samples, see the module docstring)."""
    if env == "ur5e":
        return make_ur5e_shard(seed, start, n, near)
    base = make_scene(env, seed=0)
    robot = base.robot
    q = robot.sample(n, seed=[seed, start])
    scene_seed = seed * SCENE_SEED_STRIDE + start + np.arange(n, dtype=np.int64)
    rng = np.random.default_rng([seed, start, 11])
    is_near = rng.random(n) < near if near > 0 else np.zeros(n, bool)
    if env in RANDOM_ENVS:
        scenes = [make_scene(env, seed=int(s)) for s in scene_seed]
        for i in np.flatnonzero(is_near):
            q[i] = near_boundary(scenes[i], 1, rng)[0]
        labels = [signed_distance_and_grad(s, qi[None]) for s, qi in zip(scenes, q, strict=True)]
        d = np.concatenate([lab[0] for lab in labels])
        grad = np.concatenate([lab[1] for lab in labels])
        polys = [list(s.obstacles) for s in scenes]
    else:
        q[is_near] = near_boundary(base, int(is_near.sum()), rng)
        chunks = [signed_distance_and_grad(base, c) for c in np.array_split(q, -(-n // 500))]
        d, grad = (np.concatenate(x) for x in zip(*chunks, strict=True))  # no nested pools
        polys = [list(base.obstacles)] * n
    obstacles, sizes = pad_polygons(polys)
    nodes = robot.node_positions(q).astype(np.float32)
    return Dataset(env, q, nodes, obstacles, sizes, d, grad, scene_seed)


def _prefix_consistent(env: str, near: float) -> bool:
    """True when ``make_shard(env, seed, start, k)`` is the first k samples of any longer
    shard at ``start``: uniform a–e samples (one uniform stream seeded (seed, start), scene
    seeds by index). Near-boundary and ``ur5e`` shards draw per-shard streams of length n."""
    return env != "ur5e" and near == 0.0


def split_samples(env: str, seed: int, start: int, n: int, near: float = 0.0) -> Dataset:
    """Samples ``start … start + n − 1`` of the split of ``env`` with ``seed``, block by block
    (module docstring): the samples of ``gdnplan generate``'s shards, whatever the range.

    Each block b overlapping the range is ``make_shard(env, seed, b · SHARD_SIZE, k)``, k
    the samples of it up to the range's end (or the whole block where a shorter shard is not
    its prefix, :func:`_prefix_consistent`), with the samples before ``start`` dropped.
    """
    check_data_seed(seed)
    if n < 1 or start < 0:
        raise InputError(f"n: expected n ≥ 1 samples from start ≥ 0, got n = {n}, start = {start}")
    size, end = SHARD_SIZE, start + n
    parts = []
    for block in range(start // size * size, end, size):
        stop = min(end, block + size) - block  # the range's end within the block
        part = make_shard(env, seed, block, stop if _prefix_consistent(env, near) else size, near)
        parts.append(part.subset(slice(max(start - block, 0), stop)))
    return parts[0] if len(parts) == 1 else concat(parts)
