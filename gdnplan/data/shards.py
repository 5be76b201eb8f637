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

from pathlib import Path

from tqdm import tqdm

from ..errors import UnknownNameError
from . import sampling
from .dataset import ENVS
from .sampling import SHARD_SIZE as SHARD_SIZE  # re-exported; read as sampling.SHARD_SIZE
from .shard_folder import MANIFEST as MANIFEST  # re-exported
from .shard_folder import check_manifest, check_split, missing_shards, run_jobs, shard_plan


def _write_shard(job: tuple[str, int, int, int, str, float]) -> int:
    env, seed, start, n, path, near = job
    sampling.split_samples(env, seed, start, n, near).save(path)
    return n


def shard_paths(out_dir: Path | str, n: int) -> list[tuple[int, int, Path]]:
    """(start, size, path) of every shard of an n-sample split in ``out_dir``."""
    return shard_plan(out_dir, n, sampling.SHARD_SIZE)


MANIFEST_OPTIONS = {"env": "--env", "seed": "--seed", "near": "--near", "shard_size": "SHARD_SIZE"}


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
        n: number of samples, 1 … ``MAX_SPLIT`` (10⁸; ~150 B to ~1.1 kB of disk each).
        seed: split seed (train 0, test 1 by convention, see ``SPLITS``).
        out_dir: directory of the shards (created).
        workers: processes, an int in 1 … ``MAX_WORKERS`` (default None: all cores).
        near: fraction of near-contact samples (module docstring: around the fetch task for
            ``ur5e``, at the collision boundary for a–e).

    Returns:
        ``out_dir``.
    """
    if env not in ENVS:
        raise UnknownNameError(f"env: unknown environment {env!r}; choose one of {list(ENVS)}")
    check_split(n, near, workers, seed)
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    size = sampling.SHARD_SIZE
    settings = {"env": env, "seed": int(seed), "near": float(near), "shard_size": size}
    check_manifest(out_dir, settings, MANIFEST_OPTIONS)
    jobs = [(env, seed, s, k, str(p), near) for s, k, p in missing_shards(out_dir, n, size)]
    done = n - sum(j[3] for j in jobs)
    with tqdm(total=n, initial=done, desc=f"generate {env} → {out_dir}", unit="sample") as bar:
        run_jobs(_write_shard, jobs, workers, bar)
    return out_dir
