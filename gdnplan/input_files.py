"""Input files, read whole and bounded.

Input files (problem files, URDF and SRDF files, point files, weights cards) are read with
:func:`read_input`: a regular file (a symlink to one is fine) of at most ``MAX_INPUT_BYTES``,
else an InputError naming it, so a FIFO never blocks, ``/dev/zero`` or a huge sparse file
never fills the memory.
"""

from __future__ import annotations

import os
import stat
from pathlib import Path

from .errors import InputError

MAX_INPUT_BYTES = 1 << 28  # 256 MiB: the largest input file read (2 000 000 cloud points as text)


def read_input(path: Path | str, what: str, limit: int = MAX_INPUT_BYTES) -> bytes:
    """The bytes of the input file ``path``, read whole.

    Raises:
        InputError: naming ``what`` and the path, when it cannot be opened (missing, no
            permission), is a directory, is not a regular file (a FIFO, a device such as
            ``/dev/zero``, a socket; opened without blocking), or holds more than ``limit``
            bytes (checked before reading and while reading: a file growing meanwhile).
    """
    path = Path(path)
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK)  # a FIFO opens without a writer
    except (OSError, ValueError) as e:  # ValueError: a NUL byte in the name
        why = e.strerror if isinstance(e, OSError) and e.strerror else str(e)
        raise InputError(f"{what}: cannot read {path} ({why})") from e
    try:
        _check_input_stat(os.fstat(fd), path, what, limit)
        data = _read_fd(fd, limit + 1)
    except OSError as e:
        raise InputError(f"{what}: cannot read {path} ({e.strerror or e})") from e
    finally:
        os.close(fd)
    if len(data) > limit:
        raise InputError(_too_large(path, what, limit))
    return data


def check_input_file(path: Path | str, what: str, limit: int = MAX_INPUT_BYTES) -> Path:
    """``path`` when it is a regular file of at most ``limit`` bytes, for a reader that opens
    it itself (assimp's mesh loader); InputError as :func:`read_input` otherwise."""
    path = Path(path)
    try:
        st = os.stat(path)
    except (OSError, ValueError) as e:
        why = e.strerror if isinstance(e, OSError) and e.strerror else str(e)
        raise InputError(f"{what}: cannot read {path} ({why})") from e
    _check_input_stat(st, path, what, limit)
    return path


def _check_input_stat(st: os.stat_result, path: Path, what: str, limit: int) -> None:
    """InputError unless ``st`` is a regular file of at most ``limit`` bytes."""
    if stat.S_ISDIR(st.st_mode):
        raise InputError(f"{what}: {path} is a directory; give a file")
    if not stat.S_ISREG(st.st_mode):
        raise InputError(
            f"{what}: {path} is not a regular file (a device, FIFO or socket); give a file"
        )
    if st.st_size > limit:
        raise InputError(_too_large(path, what, limit))


def _read_fd(fd: int, n: int) -> bytes:
    """At most ``n`` bytes from the file descriptor ``fd``, up to its end."""
    chunks, size = [], 0
    while size < n:
        chunk = os.read(fd, min(n - size, 1 << 24))
        if not chunk:
            break
        chunks.append(chunk)
        size += len(chunk)
    return b"".join(chunks)


def _too_large(path: Path, what: str, limit: int) -> str:
    return f"{what}: {path} is larger than {limit} bytes (the most an input file may hold)"
