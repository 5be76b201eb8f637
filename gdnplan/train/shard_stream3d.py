"""The 3-D training split as a stream of shards: its files, one shard's arrays, an epoch's batches.

A split is a folder of shards (:mod:`gdnplan.data.shards3d`); only one shard is in memory at a
time. Epoch e visits the shards in a permutation seeded by (seed, e) and the rows of each shard
in a permutation seeded by (seed, e, shard), in batches of ``batch`` rows (a shard's last,
shorter batch included); :func:`batches` starts at any step, so a resumed run sees the same
batches as one trained straight through.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..data.shard_read import FIX, read_npz
from ..errors import InputError


def shard_files(folder: Path | str) -> list[Path]:
    files = sorted(p for p in Path(folder).glob("shard_*.npz") if not p.name.endswith(".tmp.npz"))
    if not files:
        raise InputError(f"data: no shards in {folder}; run `gdnplan generate --env ur5e_boxes`")
    return files


def read_shard(path: Path) -> dict:
    """The arrays of the 3-D shard ``path``, checked as :func:`gdnplan.data.shard_read.read_npz`
    checks them (a readable archive of finite numbers; InputError naming the file)."""
    arrays = read_npz(path)
    if "d" not in arrays or arrays["d"].ndim != 1:
        raise InputError(f"data: shard {path} has no distances 'd' (n,); {FIX}")
    return arrays


def batches(files: list[Path], batch: int, seed: int, epoch: int, skip: int = 0):
    """(step, shard arrays, rows) of one epoch (module docstring), from step ``skip`` on."""
    order = np.random.default_rng([seed, epoch]).permutation(len(files))
    step = 0
    for f in order:
        shard = None
        n = len(read_shard(files[f])["d"]) if step + 1 <= skip else None
        if n is not None:
            count = -(-n // batch)
            if step + count <= skip:
                step += count
                continue
        shard = read_shard(files[f])
        perm = np.random.default_rng([seed, epoch, int(f)]).permutation(len(shard["d"]))
        for s in range(0, len(perm), batch):
            if step >= skip:
                yield step, shard, perm[s : s + batch]
            step += 1


def split_env(folder: Path | str) -> str:
    """The environment of a split folder (its first shard's ``env``)."""
    return str(read_shard(shard_files(folder)[0])["env"])


__all__ = ["batches", "read_shard", "shard_files", "split_env"]
