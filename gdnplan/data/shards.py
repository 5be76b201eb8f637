"""Writing a split as resumable ``.npz`` shards (:func:`generate`).

Shards of ``SHARD_SIZE`` samples (the blocks of :func:`.sampling.split_samples`, the routine
:func:`gdnplan.metrics.test_set` draws from too) are written by a pool of processes, each to a
temporary file renamed when complete (:func:`gdnplan.files.atomic_path`).

Resuming: the folder's ``manifest.json`` records the settings of its split (env, seed, near,
shard size), written before the first shard. Running :func:`generate` again with the same
settings continues the split: shard k holds samples k · SHARD_SIZE … of the n asked for, so
shards that exist with exactly that size are kept, a shorter last shard of a smaller earlier
n is made again at its full size, and the missing ones are made; the folder then holds the
same n samples as a one-shot run of n. Other settings (another env, seed or near), a smaller n
than the folder already holds, or shards without a manifest are refused with an InputError
naming the setting, never mixed into the split.
"""

from __future__ import annotations

import json
import os
from multiprocessing import get_context
from pathlib import Path

import numpy as np
from tqdm import tqdm

from ..errors import InputError, UnknownNameError
from ..files import write_text
from . import sampling
from .dataset import ENVS
from .sampling import SHARD_SIZE as SHARD_SIZE  # re-exported; read as sampling.SHARD_SIZE


def _write_shard(job: tuple[str, int, int, int, str, float]) -> int:
    env, seed, start, n, path, near = job
    sampling.split_samples(env, seed, start, n, near).save(path)
    return n


def shard_paths(out_dir: Path | str, n: int) -> list[tuple[int, int, Path]]:
    """(start, size, path) of every shard of an n-sample split in ``out_dir``."""
    out_dir, size = Path(out_dir), sampling.SHARD_SIZE
    return [
        (start, min(size, n - start), out_dir / f"shard_{start // size:04d}.npz")
        for start in range(0, n, size)
    ]


MANIFEST = "manifest.json"
MANIFEST_OPTIONS = {"env": "--env", "seed": "--seed", "near": "--near", "shard_size": "SHARD_SIZE"}


def _check_manifest(out_dir: Path, settings: dict) -> None:
    """Write ``out_dir``'s manifest, or check that it records ``settings`` (InputError if not)."""
    path = out_dir / MANIFEST
    if not path.exists():
        if any(out_dir.glob("shard_*.npz")):
            raise InputError(
                f"data: {out_dir} holds shards but no {MANIFEST}, so their settings cannot be "
                "checked; move them away or generate into another --data folder"
            )
        write_text(path, json.dumps(settings, indent=2) + "\n", "--data")
        return
    try:
        recorded = json.loads(path.read_text())
    except (ValueError, OSError) as e:
        raise InputError(f"data: {path} is not a readable manifest ({e}); move the folder") from e
    for key, option in MANIFEST_OPTIONS.items():
        if not isinstance(recorded, dict) or recorded.get(key) != settings[key]:
            was = recorded.get(key) if isinstance(recorded, dict) else None
            raise InputError(
                f"{option}: {out_dir} holds a split made with {key} = {was!r}, not "
                f"{settings[key]!r} ({MANIFEST}); use the same setting to continue it, or "
                "another --data folder"
            )


def _shard_size(path: Path) -> int | None:
    """Samples in the shard ``path`` (None when it cannot be read: it is made again)."""
    try:
        with np.load(path) as z:
            return len(z["q"])
    except (OSError, ValueError, KeyError):
        return None


def _missing_shards(out_dir: Path, n: int) -> list[tuple[int, int, Path]]:
    """The shards of an n-sample split still to make in ``out_dir`` (module docstring);
    InputError when the folder holds more than n samples."""
    plan = shard_paths(out_dir, n)
    names = {p.name for _, _, p in plan}
    shards = [p for p in out_dir.glob("shard_*.npz") if not p.name.endswith(".tmp.npz")]
    extra = [p for p in shards if p.name not in names]
    sizes = {p: _shard_size(p) for _, _, p in plan if p.exists()}
    if extra or any((sizes.get(p) or 0) > k for _, k, p in plan):
        held = sum(_shard_size(p) or 0 for p in shards)
        raise InputError(
            f"--n: {out_dir} already holds {held} samples of this split, more than n = {n}; "
            f"ask for n ≥ {held} to continue it, or use another --data folder"
        )
    return [(s, k, p) for s, k, p in plan if sizes.get(p) != k]


def generate(
    env: str,
    n: int,
    seed: int,
    out_dir: Path | str,
    workers: int | None = None,
    near: float = 0.0,
) -> Path:
    """Write an n-sample split of ``env`` as shards in ``out_dir``, or continue the one there
    (finished shards are kept; other settings are refused, see the module docstring).

    Args:
        env: environment name (``"a"`` … ``"e"``, ``"ur5e"``).
        n: number of samples.
        seed: split seed (train 0, test 1 by convention, see ``SPLITS``).
        out_dir: directory of the shards (created).
        workers: processes (default: all cores).
        near: fraction of near-contact samples (module docstring: around the fetch task for
            ``ur5e``, at the collision boundary for a–e).

    Returns:
        ``out_dir``.
    """
    if env not in ENVS:
        raise UnknownNameError(f"env: unknown environment {env!r}; choose one of {list(ENVS)}")
    if n < 1:
        raise InputError(f"n: expected a positive number of samples, got {n}")
    if not 0.0 <= near <= 1.0:
        raise InputError(f"near: expected a fraction in [0, 1], got {near}")
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    size = sampling.SHARD_SIZE
    settings = {"env": env, "seed": int(seed), "near": float(near), "shard_size": size}
    _check_manifest(out_dir, settings)
    jobs = [(env, seed, s, k, str(p), near) for s, k, p in _missing_shards(out_dir, n)]
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
