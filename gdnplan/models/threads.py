"""Torch threads for the learned models' inference.

The planner asks a learned model for tens of check points at a time: ops that small gain
nothing from torch's intra-op threads (one per core by default), and threads that wait on
cores other jobs hold make every call slower (``benchmarks/threads.py`` measures both counts
side by side). So GraphDistNet and ClearanceNet run their inference under a thread count of
their own, ``model.threads``:

- an integer in 1 … :data:`MAX_THREADS`: that many threads;
- ``None`` (the default): the library default, :func:`inference_threads`, which is 1 unless
  :func:`set_inference_threads` changed it (the CLI's ``--threads``).

:func:`torch_threads` sets the count around each call and restores the caller's afterwards
(a cheap call: ``benchmarks/threads.py`` compares switching per call with a fixed count), so
the caller's own torch work keeps its setting. Torch's thread count is process-wide: two Python
threads running inference under different counts at the same time see each other's setting.
Training (:mod:`gdnplan.train`) uses torch's global setting (``gdnplan train --threads``), not
this one. DiffCo is numpy only.

Every thread count the library or the CLI takes (``threads=`` of the models and
:func:`~gdnplan.load_model`, :func:`set_inference_threads`, every ``--threads``) passes
:func:`check_threads`: an integer (not a bool) from 1 to :data:`MAX_THREADS`, four per core
and at least 256. More threads than that never run faster, and counts far beyond it make
OpenMP fail to allocate its pool (``libgomp: Out of memory``) or raise MemoryError inside the
first inference instead of a clear error here.
"""

from __future__ import annotations

import os
from collections.abc import Iterator
from contextlib import contextmanager

from ..limits import check_int

DEFAULT_THREADS = 1
MAX_THREADS = max(256, 4 * (os.cpu_count() or 1))  # the largest count accepted (docstring)
THREADS_LIMIT = "the limit: 4 per core, at least 256"  # why MAX_THREADS, in messages
_DEFAULT = {"threads": DEFAULT_THREADS}


def check_threads(threads: object, name: str = "threads", default: bool = True) -> int | None:
    """``threads`` when it is None (only with ``default``) or an integer in 1 …
    :data:`MAX_THREADS` (bools refused), else InputError naming ``name``."""
    if threads is None and default:
        return None
    note = THREADS_LIMIT + ("; or None: the default" if default else "")
    return check_int(threads, name, 1, MAX_THREADS, note)


def inference_threads() -> int:
    """The torch threads of learned models whose ``threads`` is None (1 unless set)."""
    return _DEFAULT["threads"]


def set_inference_threads(threads: int) -> None:
    """Set the torch threads of learned models whose ``threads`` is None (an integer in
    1 … :data:`MAX_THREADS`)."""
    _DEFAULT["threads"] = check_threads(threads, default=False)


@contextmanager
def torch_threads(threads: int | None) -> Iterator[int]:
    """Run the block with ``threads`` torch intra-op threads (None: :func:`inference_threads`),
    then restore the count the caller had; yields the count used."""
    import torch

    checked = check_threads(threads)
    n = inference_threads() if checked is None else checked
    before = torch.get_num_threads()
    if n == before:
        yield n
        return
    torch.set_num_threads(n)
    try:
        yield n
    finally:
        torch.set_num_threads(before)
