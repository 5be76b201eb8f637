"""Datasets of configurations, obstacle sets and coal labels, written as resumable ``.npz`` shards.

A sample is a configuration q drawn uniformly within the joint limits, the obstacle polygons of
its scene and the coal labels: the signed distance f_cd(q) (m) and its gradient ∂f/∂q (m/rad).
Fixed environments (a, c) share one scene; random environments (b, d, e) draw a new obstacle
set per sample with ``make_scene(env, seed=scene_seed)``, where

    scene_seed = seed · 10⁸ + index     (index = position of the sample in the split),

so a split is a pure function of (env, seed, n) and train (seed 0) and test (seed 1) never
share a scene. Shards of ``SHARD_SIZE`` samples are written by a pool of processes, each to a
temporary file renamed when complete; re-running skips shards that exist.

Shard arrays (n samples, P obstacles of at most V vertices, N robot nodes):

========== ================= ====================================================
q          (n, dof) float64  joint angles (rad)
nodes      (n, N, 2) float32 robot graph nodes (link polygon vertices) at q (m)
obstacles  (n, P, V, 2)      obstacle polygons, CCW, zero-padded (m)
sizes      (n, P) int32      vertex count of each polygon (0 = no polygon)
d          (n,) float64      coal signed distance (m)
grad       (n, dof) float64  coal ∂f/∂q
scene_seed (n,) int64        seed of the sample's scene
========== ================= ====================================================
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from multiprocessing import get_context
from pathlib import Path

import numpy as np
from tqdm import tqdm

from .distance import signed_distance_and_grad
from .errors import InputError, UnknownNameError
from .scene import ENV_ROBOT, Scene, make_scene

SHARD_SIZE = 2500
RANDOM_ENVS = ("b", "d", "e")
SPLITS = {"train": (0, 50_000), "test": (1, 5_000)}  # split -> (seed, paper's size)
DATA_DIR = Path(__file__).resolve().parent.parent / "data"
FIELDS = ("q", "nodes", "obstacles", "sizes", "d", "grad", "scene_seed")


@dataclass(frozen=True)
class Dataset:
    """Samples of one environment (see the module docstring for the arrays)."""

    env: str
    q: np.ndarray
    nodes: np.ndarray
    obstacles: np.ndarray
    sizes: np.ndarray
    d: np.ndarray
    grad: np.ndarray
    scene_seed: np.ndarray

    def __len__(self) -> int:
        return len(self.q)

    def subset(self, index: np.ndarray | slice) -> Dataset:
        """The samples at ``index`` (an index array or a slice)."""
        return Dataset(self.env, *(getattr(self, f)[index] for f in FIELDS))

    def scene(self, i: int) -> Scene:
        """The scene of sample i (its robot and obstacle polygons)."""
        polys = [self.obstacles[i, p, :s] for p, s in enumerate(self.sizes[i]) if s > 0]
        polys = tuple(np.asarray(p, float) for p in polys)
        return Scene(make_scene(self.env).robot, polys, name=self.env)

    def save(self, path: Path | str, compact: bool = False) -> None:
        """Write one ``.npz`` (atomic). ``compact`` drops ``nodes`` and stores float32 polygons."""
        path = Path(path)
        arrays = {f: getattr(self, f) for f in FIELDS}
        if compact:
            arrays["nodes"] = np.zeros((len(self), 0, 2), np.float32)
            arrays["obstacles"] = arrays["obstacles"].astype(np.float32)
        tmp = path.with_name(path.name + ".tmp.npz")
        np.savez_compressed(tmp, env=np.array(self.env), **arrays)
        os.replace(tmp, path)


def pad_polygons(polys: list[list[np.ndarray]]) -> tuple[np.ndarray, np.ndarray]:
    """Stack per-sample polygon lists into (n, P, V, 2) zero-padded arrays and (n, P) sizes."""
    n_poly = max(len(ps) for ps in polys)
    n_vert = max(len(p) for ps in polys for p in ps)
    out = np.zeros((len(polys), n_poly, n_vert, 2))
    sizes = np.zeros((len(polys), n_poly), np.int32)
    for i, ps in enumerate(polys):
        for j, p in enumerate(ps):
            out[i, j, : len(p)] = p
            sizes[i, j] = len(p)
    return out, sizes


def make_shard(env: str, seed: int, start: int, n: int) -> Dataset:
    """Samples ``start … start + n − 1`` of the split of ``env`` with ``seed``."""
    base = make_scene(env, seed=0)
    robot = base.robot
    q = robot.sample(n, seed=[seed, start])
    scene_seed = seed * 10**8 + start + np.arange(n, dtype=np.int64)
    if env in RANDOM_ENVS:
        scenes = [make_scene(env, seed=int(s)) for s in scene_seed]
        labels = [signed_distance_and_grad(s, qi[None]) for s, qi in zip(scenes, q, strict=True)]
        d = np.concatenate([lab[0] for lab in labels])
        grad = np.concatenate([lab[1] for lab in labels])
        polys = [list(s.obstacles) for s in scenes]
    else:
        chunks = [signed_distance_and_grad(base, c) for c in np.array_split(q, -(-n // 500))]
        d, grad = (np.concatenate(x) for x in zip(*chunks, strict=True))  # no nested pools
        polys = [list(base.obstacles)] * n
    obstacles, sizes = pad_polygons(polys)
    nodes = robot.node_positions(q).astype(np.float32)
    return Dataset(env, q, nodes, obstacles, sizes, d, grad, scene_seed)


def _write_shard(job: tuple[str, int, int, int, str]) -> int:
    env, seed, start, n, path = job
    make_shard(env, seed, start, n).save(path)
    return n


def shard_paths(out_dir: Path | str, n: int) -> list[tuple[int, int, Path]]:
    """(start, size, path) of every shard of an n-sample split in ``out_dir``."""
    out_dir = Path(out_dir)
    return [
        (start, min(SHARD_SIZE, n - start), out_dir / f"shard_{start // SHARD_SIZE:04d}.npz")
        for start in range(0, n, SHARD_SIZE)
    ]


def generate(env: str, n: int, seed: int, out_dir: Path | str, workers: int | None = None) -> Path:
    """Write an n-sample split of ``env`` as shards in ``out_dir``; finished shards are kept.

    Args:
        env: environment name (``"a"`` … ``"e"``).
        n: number of samples.
        seed: split seed (train 0, test 1 by convention, see ``SPLITS``).
        out_dir: directory of the shards (created).
        workers: processes (default: all cores).

    Returns:
        ``out_dir``.
    """
    if env not in ENV_ROBOT:
        raise UnknownNameError(f"env: unknown environment {env!r}; choose one of {list(ENV_ROBOT)}")
    if n < 1:
        raise InputError(f"n: expected a positive number of samples, got {n}")
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    jobs = [(env, seed, s, k, str(p)) for s, k, p in shard_paths(out_dir, n) if not p.exists()]
    done = n - sum(j[3] for j in jobs)
    workers = min(workers or os.cpu_count() or 1, max(len(jobs), 1))
    with tqdm(total=n, initial=done, desc=f"generate {env} → {out_dir}", unit="sample") as bar:
        if workers < 2:
            for job in jobs:
                bar.update(_write_shard(job))
        else:
            with get_context("fork").Pool(workers) as pool:
                for k in pool.imap_unordered(_write_shard, jobs):
                    bar.update(k)
    return out_dir


def load(path: Path | str, n: int | None = None) -> Dataset:
    """Load a split (a directory of shards, or one ``.npz``), at most its first n samples."""
    path = Path(path)
    files = sorted(path.glob("shard_*.npz")) if path.is_dir() else [path] * path.exists()
    files = [f for f in files if not f.name.endswith(".tmp.npz")]
    if not files:
        raise InputError(f"data: no shards in {path}; run `gdnplan generate` first")
    parts = []
    total = 0
    for f in files:
        with np.load(f) as z:
            parts.append({k: z[k] for k in ("env", *FIELDS)})
        total += len(parts[-1]["q"])
        if n is not None and total >= n:
            break
    n_poly = max(p["obstacles"].shape[1] for p in parts)
    n_vert = max(p["obstacles"].shape[2] for p in parts)
    for p in parts:
        o, s = p["obstacles"], p["sizes"]
        p["obstacles"] = np.pad(
            o, ((0, 0), (0, n_poly - o.shape[1]), (0, n_vert - o.shape[2]), (0, 0))
        )
        p["sizes"] = np.pad(s, ((0, 0), (0, n_poly - s.shape[1])))
    arrays = [np.concatenate([p[f] for p in parts])[:n] for f in FIELDS]
    return Dataset(str(parts[0]["env"]), *arrays)


def split_dir(env: str, split: str, root: Path | str = DATA_DIR) -> Path:
    """``data/<env>/<split>``."""
    return Path(root) / env / split
