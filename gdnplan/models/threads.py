"""Torch threads for the learned models' inference.

The planner asks a learned model for tens of check points at a time: ops that small gain
nothing from torch's intra-op threads (one per core by default), and threads that wait on
cores other jobs hold make every call slower (``benchmarks/threads.py`` measures both counts
side by side). So GraphDistNet and ClearanceNet run their inference under a thread count of
their own, ``model.threads``:

- an integer ≥ 1: that many threads;
- ``None`` (the default): the library default, :func:`inference_threads`, which is 1 unless
  :func:`set_inference_threads` changed it (the CLI's ``--threads``).

:func:`torch_threads` sets the count around each call and restores the caller's afterwards
(a cheap call: ``benchmarks/threads.py`` compares switching per call with a fixed count), so
the caller's own torch work keeps its setting. Torch's thread count is process-wide: two Python
threads running inference under different counts at the same time see each other's setting.
Training (:mod:`gdnplan.train`) uses torch's global setting (``gdnplan train --threads``), not
this one. DiffCo is numpy only.
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager

from ..errors import InputError

DEFAULT_THREADS = 1
_DEFAULT = {"threads": DEFAULT_THREADS}


def check_threads(threads: object, name: str = "threads") -> int | None:
    """``threads`` when it is None or an integer ≥ 1, else InputError naming ``name``."""
    if threads is None:
        return None
    if isinstance(threads, bool) or not isinstance(threads, int) or threads < 1:
        raise InputError(f"{name}: expected an integer ≥ 1 (or None: the default), got {threads!r}")
    return threads


def inference_threads() -> int:
    """The torch threads of learned models whose ``threads`` is None (1 unless set)."""
    return _DEFAULT["threads"]


def set_inference_threads(threads: int) -> None:
    """Set the torch threads of learned models whose ``threads`` is None (integer ≥ 1)."""
    if check_threads(threads) is None:
        raise InputError("threads: expected an integer ≥ 1, got None")
    _DEFAULT["threads"] = threads


@contextmanager
def torch_threads(threads: int | None) -> Iterator[int]:
    """Run the block with ``threads`` torch intra-op threads (None: :func:`inference_threads`),
    then restore the count the caller had; yields the count used."""
    import torch

    n = inference_threads() if check_threads(threads) is None else threads
    before = torch.get_num_threads()
    if n == before:
        yield n
        return
    torch.set_num_threads(n)
    try:
        yield n
    finally:
        torch.set_num_threads(before)
