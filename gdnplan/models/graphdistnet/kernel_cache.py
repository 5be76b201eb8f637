"""Numba's on-disk cache of the compiled kernels, kept in step with their sources.

numba (``cache=True``) keys a cached function on its own source file's modification time and
size only. The kernels call one another across modules (:mod:`.fused_net_kernels` inlines
:mod:`.fused_net_readout`, :mod:`.fused_net_distances`, :mod:`.fused`, :mod:`.gemm`; the 3-D
kernels call the planar ones), so a change to a callee's file leaves its callers' cached machine
code in place, with the old callee compiled in: a checkout that pulls a change to one kernel
file would run stale code without an error. :func:`purge_stale` compares one digest of every
kernel source with the digest stored beside the cache and, when they differ, deletes the cached
kernels of all of them (numba compiles them again on first use, ≈ 1 min).
"""

from __future__ import annotations

import hashlib
from pathlib import Path

_PACKAGE = Path(__file__).resolve().parent.parent  # gdnplan/models
KERNEL_SOURCES = ("graphdistnet/fused*.py", "graphdistnet/gemm.py", "graphdistnet3d/fused3d*.py")
STAMP = "numba_kernels.sha256"  # in graphdistnet/__pycache__


def sources(root: Path = _PACKAGE) -> list[Path]:
    """The kernel modules under ``root`` (gdnplan/models), sorted."""
    return sorted(p for pattern in KERNEL_SOURCES for p in root.glob(pattern))


def digest(files: list[Path]) -> str:
    """sha256 over the files' names and bytes."""
    h = hashlib.sha256()
    for f in files:
        h.update(f.name.encode() + b"\0" + f.read_bytes() + b"\0")
    return h.hexdigest()


def purge_stale(root: Path = _PACKAGE) -> bool:
    """Delete the cached kernels (``*.nbi``, ``*.nbc`` in the kernel packages' ``__pycache__``)
    when any kernel source changed since the stamp was written; write the stamp. True when
    it purged. A read-only install (no stamp can be written) is left as it is: only a
    whole-package install writes there, and that replaces every file (all caches invalid)."""
    files = sources(root)
    caches = sorted({f.parent / "__pycache__" for f in files})
    stamp = root / "graphdistnet" / "__pycache__" / STAMP
    now = digest(files)
    try:
        if stamp.is_file() and stamp.read_text() == now:
            return False
        for cache in caches:
            for pattern in ("*.nbi", "*.nbc"):
                for old in cache.glob(pattern):
                    old.unlink(missing_ok=True)
        stamp.parent.mkdir(exist_ok=True)
        stamp.write_text(now)
    except OSError:
        return False
    return True
