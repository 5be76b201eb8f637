"""Reading a shard (``.npz``) as untrusted input: :func:`read_npz` and the planar shard's
layout, :func:`check_planar`.

A shard is read by training and evaluation long after it was written, maybe by another version,
maybe damaged (a copy cut short, a disk error) or not a shard at all. Every failure is an
InputError naming the file and the fix, never numpy's or zipfile's error from deep inside a
training run:

- the file: a regular file of at most ``MAX_INPUT_BYTES`` (:func:`gdnplan.files.check_input_file`)
  that is a zip archive of ``.npy`` arrays;
- each array's header, before it is read: no object dtype (no pickle), and all arrays together
  at most :data:`MAX_SHARD_BYTES` once decompressed (a compressed array of zeros claims 1000×
  its size on disk);
- the values: every floating array finite (a NaN label made the first epoch "diverge", blaming
  the learning rate).

:func:`check_planar` then checks the arrays of a planar shard (:mod:`.dataset`) against each
other: the fields present, their dtypes (real q, d, grad, nodes, obstacles; integer sizes,
seeds, grippers) and shapes (one sample count n; q and grad (n, dof); nodes (n, N, 2);
obstacles (n, P, V, 2) with sizes (n, P)).
"""

from __future__ import annotations

import math
import zipfile
import zlib
from pathlib import Path

import numpy as np

from ..errors import InputError
from ..files import check_input_file

MAX_SHARD_BYTES = 1 << 30  # decompressed bytes of one shard's arrays (a 2 500-sample one: ~3 MB)
FIX = "delete it and run `gdnplan generate` again (finished shards are kept)"
REAL = ("q", "nodes", "obstacles", "d", "grad", "stick")
INTEGER = ("sizes", "scene_seed", "gripper")


def read_npz(path: Path | str, what: str = "data") -> dict[str, np.ndarray]:
    """Every array of the shard ``path`` (module docstring); InputError "<what>: shard …"."""
    path = Path(path)
    check_input_file(path, f"{what}: shard")
    try:
        with zipfile.ZipFile(path) as zf:
            headers = {m.filename: _header(zf, m.filename) for m in zf.infolist()}
            total = sum(math.prod(shape) * dtype.itemsize for shape, dtype in headers.values())
            if total > MAX_SHARD_BYTES:
                raise InputError(
                    f"{what}: shard {path} claims {total:,} bytes of arrays, more than "
                    f"{MAX_SHARD_BYTES:,} (a shard of the generator holds a few MB); {FIX}"
                )
        with np.load(path, allow_pickle=False) as z:
            arrays = {k: z[k] for k in z.files}
    except InputError:
        raise
    except (OSError, ValueError, EOFError, KeyError, zipfile.BadZipFile, zlib.error) as e:
        why = " ".join(str(e).split())[:200]
        raise InputError(
            f"{what}: shard {path} is not a readable .npz of arrays ({type(e).__name__}: "
            f"{why}); {FIX}"
        ) from e
    for name, a in arrays.items():
        if a.dtype.kind in "fc" and not np.isfinite(a).all():
            raise InputError(f"{what}: shard {path} array {name!r} holds NaN or inf values; {FIX}")
    return arrays


def _header(zf: zipfile.ZipFile, member: str) -> tuple[tuple[int, ...], np.dtype]:
    """(shape, dtype) from the ``.npy`` header of ``member``; ValueError for anything else,
    an object dtype included."""
    with zf.open(member) as f:
        version = np.lib.format.read_magic(f)
        readers = {
            (1, 0): np.lib.format.read_array_header_1_0,
            (2, 0): np.lib.format.read_array_header_2_0,
        }
        if version not in readers:
            raise ValueError(f"{member}: .npy format version {version}")
        shape, _, dtype = readers[version](f)
    if dtype.hasobject:
        raise ValueError(f"{member} holds Python objects (a pickle), not numbers")
    return shape, dtype


def check_planar(arrays: dict[str, np.ndarray], path: Path, fields: tuple[str, ...]) -> None:
    """InputError naming the shard ``path`` and the array unless ``arrays`` hold the planar
    shard ``fields`` (plus ``env``) with the dtypes and shapes of the module docstring."""

    def bad(name: str, why: str) -> InputError:
        return InputError(f"data: shard {path} array {name!r} {why}; {FIX}")

    for name in ("env", *fields):
        if name not in arrays:
            raise bad(name, "is missing (a shard of another tool or version)")
    if arrays["env"].dtype.kind != "U" or arrays["env"].shape != ():
        raise bad("env", "is not an environment name")
    for name, a in arrays.items():
        if name in REAL and a.dtype.kind not in "fiu":
            raise bad(name, f"holds {a.dtype} values, not real numbers")
        if name in INTEGER and a.dtype.kind not in "iu":
            raise bad(name, f"holds {a.dtype} values, not integers")
    q, obstacles = arrays["q"], arrays["obstacles"]
    if q.ndim != 2 or q.shape[1] < 1:
        raise bad("q", f"has shape {q.shape}, expected (n, dof)")
    n, dof = q.shape
    if obstacles.ndim != 4 or obstacles.shape[0] != n or obstacles.shape[3] != 2:
        raise bad("obstacles", f"has shape {obstacles.shape}, expected (n, P, V, 2) (n = {n})")
    p, v = obstacles.shape[1:3]
    expected = {
        "q": (n, dof),
        "d": (n,),
        "grad": (n, dof),
        "scene_seed": (n,),
        "sizes": (n, p),
        "gripper": (n,),
        "stick": (n, 2),
    }
    for name, a in arrays.items():
        shape = expected.get(name)
        if name == "nodes":
            ok = a.ndim == 3 and a.shape[0] == n and a.shape[2] == 2
        else:
            ok = shape is None or a.shape == shape
        if not ok:
            want = "(n, N, 2)" if name == "nodes" else str(shape)
            raise bad(name, f"has shape {a.shape}, expected {want} (n = {n}, dof = {dof})")
    if len(arrays["sizes"]) and not (0 <= arrays["sizes"].min() and arrays["sizes"].max() <= v):
        raise bad("sizes", f"holds vertex counts outside [0, {v}]")
