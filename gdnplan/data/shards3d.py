"""Writing a 3-D split as resumable ``.npz`` shards (:func:`generate3d`), on a local process
pool or on a Ray cluster.

Shard k holds samples k · shard_size … of the split (:func:`gdnplan.data.samples3d.make_shard3d`,
a pure function of its settings), written to a temporary file renamed when complete. As for
the planar splits (:mod:`gdnplan.data.shards`), the folder's ``manifest.json`` records the
settings (env, seed, near, shard size) before the first shard; running again with the same
settings keeps the complete shards and makes the missing ones, other settings are refused.

Ray (``ray=ADDRESS``; ``"local"`` starts a local Ray instance, anything else is passed to
``ray.init(address=…)``, e.g. ``"auto"`` or ``"ray://head:10001"``): every missing shard is
one remote task; the driver writes the arrays the tasks return, so workers need gdnplan but
no shared file system, and the shards are the same bytes as the local pool's.
"""

from __future__ import annotations

import json
import os
from multiprocessing import get_context
from pathlib import Path

import numpy as np
from tqdm import tqdm

from ..errors import InputError
from ..files import atomic_path, write_text
from .samples3d import ENVS3D, SCENE_SAMPLES, make_shard3d
from .shards import MANIFEST, _shard_size

SHARD_SIZE3D = 1000


def shard_plan(out_dir: Path, n: int, size: int) -> list[tuple[int, int, Path]]:
    """(start, samples, path) of every shard of an n-sample split."""
    return [
        (s, min(size, n - s), out_dir / f"shard_{s // size:04d}.npz") for s in range(0, n, size)
    ]


def save_shard(arrays: dict, path: Path | str) -> None:
    """Write a shard's arrays to ``path`` atomically (compressed npz)."""
    with atomic_path(Path(path), "shard") as tmp, open(tmp, "wb") as f:
        np.savez_compressed(f, **arrays)


def _job(job: tuple[str, int, int, int, float]) -> dict:
    env, seed, start, n, near = job
    return make_shard3d(env, seed, start, n, near)


def _write(job_path: tuple[tuple, str]) -> int:
    job, path = job_path
    save_shard(_job(job), path)
    return job[3]


def _check_manifest3d(out_dir: Path, settings: dict) -> None:
    path = out_dir / MANIFEST
    if not path.exists():
        if any(out_dir.glob("shard_*.npz")):
            raise InputError(f"data: {out_dir} holds shards but no {MANIFEST}; use another folder")
        write_text(path, json.dumps(settings, indent=2) + "\n", "--data")
        return
    try:
        recorded = json.loads(path.read_text())
    except (ValueError, OSError) as e:
        raise InputError(f"data: {path} is not a readable manifest ({e}); move the folder") from e
    for key, value in settings.items():
        if not isinstance(recorded, dict) or recorded.get(key) != value:
            was = recorded.get(key) if isinstance(recorded, dict) else None
            raise InputError(
                f"--{key.replace('_', '-')}: {out_dir} holds a split made with {key} = {was!r}, "
                f"not {value!r} ({MANIFEST}); use the same setting or another --data folder"
            )


def missing_shards3d(out_dir: Path, n: int, size: int) -> list[tuple[int, int, Path]]:
    """The shards of an n-sample split still to make (InputError if the folder holds more)."""
    plan = shard_plan(out_dir, n, size)
    names = {p.name for _, _, p in plan}
    shards = [p for p in out_dir.glob("shard_*.npz") if not p.name.endswith(".tmp.npz")]
    sizes = {p: _shard_size(p) for _, _, p in plan if p.exists()}
    if any(p.name not in names for p in shards) or any((sizes.get(p) or 0) > k for _, k, p in plan):
        raise InputError(f"--n: {out_dir} holds more samples than n = {n}; ask for more")
    return [(s, k, p) for s, k, p in plan if sizes.get(p) != k]


def generate3d(
    env: str,
    n: int,
    seed: int,
    out_dir: Path | str,
    workers: int | None = None,
    near: float = 0.0,
    ray: str | None = None,
    shard_size: int = SHARD_SIZE3D,
) -> Path:
    """Write (or continue) an n-sample split of the 3-D environment ``env`` in ``out_dir``.

    Args:
        env: a 3-D environment (``"ur5e_boxes"``).
        n: samples; seed: the split's seed (train 0, test 1, hidden evaluation ≥ 2).
        workers: local processes (default: all cores); ignored with ``ray``.
        near: fraction of near-boundary samples (:mod:`.samples3d`).
        ray: None (local pool), ``"local"`` (a local Ray instance) or a Ray address.
        shard_size: samples per shard, a multiple of SCENE_SAMPLES.
    """
    if env not in ENVS3D:
        raise InputError(f"env: unknown 3-D environment {env!r}; choose one of {list(ENVS3D)}")
    if isinstance(n, bool) or not isinstance(n, int) or n < 1:
        raise InputError(f"n: expected a positive number of samples, got {n!r}")
    if not 0.0 <= near <= 1.0:
        raise InputError(f"near: expected a fraction in [0, 1], got {near}")
    if shard_size < 1 or shard_size % SCENE_SAMPLES:
        raise InputError(f"shard_size: expected a positive multiple of {SCENE_SAMPLES}")
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    settings = {"env": env, "seed": int(seed), "near": float(near), "shard_size": shard_size}
    _check_manifest3d(out_dir, settings)
    todo = missing_shards3d(out_dir, n, shard_size)
    jobs = [((env, int(seed), s, k, float(near)), str(p)) for s, k, p in todo]
    done = n - sum(j[0][3] for j in jobs)
    with tqdm(total=n, initial=done, desc=f"generate {env} → {out_dir}", unit="sample") as bar:
        if ray is not None:
            _run_ray(jobs, ray, bar)
            return out_dir
        workers = min(workers or os.cpu_count() or 1, max(len(jobs), 1))
        if workers < 2:
            for job in jobs:
                bar.update(_write(job))
        else:
            with get_context("fork").Pool(workers) as pool:
                for k in pool.imap_unordered(_write, jobs):
                    bar.update(k)
    return out_dir


def _run_ray(jobs: list, address: str, bar: tqdm) -> None:
    """Every job as a Ray task; the driver writes the shards as the tasks finish."""
    try:
        import ray
    except ImportError as e:
        raise InputError("--ray: Ray is not installed; pip install 'gdnplan[ray]'") from e
    started = not ray.is_initialized()
    if started:
        ray.init(address=None if address == "local" else address, include_dashboard=False)
    try:
        task = ray.remote(_job)
        pending = {task.remote(job): (job, path) for job, path in jobs}
        while pending:
            ready, _ = ray.wait(list(pending), num_returns=1)
            job, path = pending.pop(ready[0])
            save_shard(ray.get(ready[0]), path)
            bar.update(job[3])
    finally:
        if started:
            ray.shutdown()
