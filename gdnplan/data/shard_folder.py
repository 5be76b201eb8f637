"""A folder of resumable ``.npz`` shards: its manifest, its missing shards, the worker pool.

One split of n samples lives in one folder as shards of ``size`` samples: shard k holds samples
k · size … min((k + 1) · size, n) − 1 and is named ``shard_{k:04d}.npz``. The folder's
``manifest.json`` records the settings of the split (a dict of JSON values) before the first
shard is written; a later run with the same settings keeps every complete shard and makes the
missing ones (a shorter last shard of a smaller earlier n is made again at its full size), a
run with other settings, a smaller n than the folder holds, or shards without a manifest are
refused with an InputError naming the setting. The planar (:mod:`.shards`) and 3-D
(:mod:`.shards3d`) writers differ only in what one shard holds.
"""

from __future__ import annotations

import json
import os
import signal
from collections.abc import Callable, Mapping, Sequence
from multiprocessing import get_context
from pathlib import Path

import numpy as np
from tqdm import tqdm

from ..errors import InputError
from ..files import write_text
from ..limits import check_int, is_number
from .shard_read import read_npz

MANIFEST = "manifest.json"
MAX_SPLIT = 10**8  # samples of one split: ~15 GB of planar 2-DoF shards, ~110 GB of (e)'s
SCENE_SEED_STRIDE = 10**8  # sample i of split seed s draws its scene with seed s · stride + i
MAX_DATA_SEED = (2**63 - 1 - MAX_SPLIT) // SCENE_SEED_STRIDE  # scene seeds stay int64
MAX_WORKERS = max(64, 4 * (os.cpu_count() or 1))  # processes of one run (four per core)


def shard_plan(out_dir: Path | str, n: int, size: int) -> list[tuple[int, int, Path]]:
    """(start, samples, path) of every shard of an n-sample split of ``size``-sample shards."""
    out_dir = Path(out_dir)
    return [
        (s, min(size, n - s), out_dir / f"shard_{s // size:04d}.npz") for s in range(0, n, size)
    ]


def check_split(n: object, near: object, workers: object = None, seed: object = 0) -> None:
    """InputError unless n is an int (not a bool) in 1 … :data:`MAX_SPLIT` (a split's shards
    take ~150 bytes (planar 2-DoF) to ~1.1 kB (environment e) of disk per sample), near a
    fraction in [0, 1], workers None or an int in 1 … :data:`MAX_WORKERS` and seed an
    integer in [0, :data:`MAX_DATA_SEED`] (:func:`check_data_seed`)."""
    check_data_seed(seed)
    if isinstance(n, bool) or not isinstance(n, int | np.integer) or not 1 <= n <= MAX_SPLIT:
        raise InputError(
            f"n: expected a number of samples in [1, {MAX_SPLIT:.0e}] (the limit), got {n!r}"
        )
    if not is_number(near) or not 0.0 <= near <= 1.0:
        raise InputError(f"near: expected a fraction in [0, 1], got {near!r}")
    check_workers(workers)


def check_data_seed(seed: object) -> int:
    """A split's seed: an integer in [0, :data:`MAX_DATA_SEED`] (its scenes' seeds
    seed · 10⁸ + i, i < :data:`MAX_SPLIT`, must stay 64-bit integers), else InputError."""
    return check_int(seed, "seed", 0, MAX_DATA_SEED)


def check_workers(workers: object) -> int | None:
    """None (all cores) or an int (not a bool) in 1 … :data:`MAX_WORKERS`, else InputError."""
    if workers is None:
        return None
    if isinstance(workers, bool) or not isinstance(workers, int | np.integer):
        raise InputError(f"workers: expected None or an integer ≥ 1, got {workers!r}")
    if not 1 <= workers <= MAX_WORKERS:
        raise InputError(f"workers: {workers} is outside [1, {MAX_WORKERS}] (4 per core)")
    return int(workers)


def check_manifest(out_dir: Path, settings: Mapping, options: Mapping[str, str]) -> None:
    """Write ``out_dir``'s manifest, or check that it records ``settings`` (InputError naming
    ``options[key]``, the user's name of the setting, if not)."""
    path = out_dir / MANIFEST
    if not path.exists():
        if any(out_dir.glob("shard_*.npz")):
            raise InputError(
                f"data: {out_dir} holds shards but no {MANIFEST}, so their settings cannot be "
                "checked; move them away or generate into another --data folder"
            )
        write_text(path, json.dumps(dict(settings), indent=2) + "\n", "--data")
        return
    try:
        recorded = json.loads(path.read_text())
    except (ValueError, OSError) as e:
        raise InputError(f"data: {path} is not a readable manifest ({e}); move the folder") from e
    for key, value in settings.items():
        if not isinstance(recorded, dict) or recorded.get(key) != value:
            was = recorded.get(key) if isinstance(recorded, dict) else None
            raise InputError(
                f"{options[key]}: {out_dir} holds a split made with {key} = {was!r}, not "
                f"{value!r} ({MANIFEST}); use the same setting to continue it, or another "
                "--data folder"
            )


def shard_size(path: Path) -> int | None:
    """Samples in the shard ``path`` (None when it cannot be read, e.g. a truncated copy, or
    fails :func:`.shard_read.read_npz`'s checks: it is made again)."""
    try:
        arrays = read_npz(path)
        return len(arrays["q"]) if "q" in arrays and arrays["q"].ndim else None
    except InputError:
        return None


def missing_shards(out_dir: Path, n: int, size: int) -> list[tuple[int, int, Path]]:
    """The shards of an n-sample split still to make in ``out_dir`` (module docstring);
    InputError when the folder holds more than n samples."""
    plan = shard_plan(out_dir, n, size)
    names = {p.name for _, _, p in plan}
    shards = [p for p in out_dir.glob("shard_*.npz") if not p.name.endswith(".tmp.npz")]
    sizes = {p: shard_size(p) for _, _, p in plan if p.exists()}
    if any(p.name not in names for p in shards) or any((sizes.get(p) or 0) > k for _, k, p in plan):
        held = sum(shard_size(p) or 0 for p in shards)
        raise InputError(
            f"--n: {out_dir} already holds {held} samples of this split, more than n = {n}; "
            f"ask for n ≥ {held} to continue it, or use another --data folder"
        )
    return [(s, k, p) for s, k, p in plan if sizes.get(p) != k]


def run_jobs(
    write: Callable[[object], int], jobs: Sequence, workers: int | None, bar: tqdm
) -> None:
    """``write(job)`` (it returns its sample count) for every job, in this process or on a
    forked pool of ``workers`` processes (None: all cores; else :func:`check_workers`),
    advancing ``bar``."""
    workers = check_workers(workers)
    workers = min(workers or os.cpu_count() or 1, max(len(jobs), 1))
    if workers < 2:
        for job in jobs:
            bar.update(write(job))
        return
    # Ctrl-C reaches the whole process group: the workers ignore it (each printed a
    # KeyboardInterrupt traceback, and the pool waited for their shards, ~40 s of (d)), this
    # process raises KeyboardInterrupt and the pool's exit terminates them; the shard being
    # written stays a temp file (atomic_path), never a half shard.
    with get_context("fork").Pool(workers, initializer=_ignore_sigint) as pool:
        for k in pool.imap_unordered(write, jobs):
            bar.update(k)


def _ignore_sigint() -> None:
    """A worker's initializer: SIGINT ignored (the parent handles Ctrl-C)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
