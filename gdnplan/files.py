"""Output files: written whole or not at all, and checked before the work that produces them.

:func:`atomic_path` is the one temp-then-rename of the package. It yields a fresh temporary
path beside the target (``.<name>.<random>.tmp<suffix>``, created by ``tempfile.mkstemp`` in
the target's directory, so the rename stays on one file system); the caller's writer fills it
(matplotlib ``savefig``, Pillow, ``np.savez``, safetensors ``save_file``, JSON text), then the
file is flushed to disk (``fsync``), given the usual permissions (0o666 minus the umask) and
renamed over the target with ``os.replace``. On any failure or interrupt inside the block
(an exception, ``KeyboardInterrupt``, SIGTERM, raised as ``SystemExit(143)`` while the block
runs in the main thread) the temporary file is removed and the target is untouched. An
``OSError`` of the writer (a full disk, a read-only file system) becomes an
:class:`~gdnplan.errors.OutputError` naming the path.

Targets are regular files or nothing: an existing symlink, directory, device node, FIFO or
socket at the target is never replaced (``--animate /dev/full`` run as root used to replace the
device node). Missing parent directories are created when the file is written.

:func:`check_output_path` runs the same checks up front, before any computation: the suffix is
one the writer knows, the target is absent or a regular file, and the nearest existing
ancestor directory is a directory where a file can be created (probed by creating and
removing a temporary file).

Input files are read by :mod:`gdnplan.input_files` (:func:`read_input`, re-exported here).
"""

from __future__ import annotations

import contextlib
import os
import signal
import stat
import tempfile
import threading
from collections.abc import Iterator, Sequence
from pathlib import Path

from .errors import OutputError
from .input_files import MAX_INPUT_BYTES as MAX_INPUT_BYTES
from .input_files import check_input_file as check_input_file
from .input_files import read_input as read_input

FIGURE_SUFFIXES = (".png", ".pdf", ".svg")


def _check_target(path: Path, what: str) -> None:
    """OutputError unless ``path`` is absent or a regular file (symlinks are refused)."""
    try:
        st = os.lstat(path)
    except FileNotFoundError:
        return
    except OSError as e:  # e.g. a parent that is a regular file (ENOTDIR)
        raise OutputError(f"{what}: cannot write {path} ({e.strerror})") from e
    if stat.S_ISLNK(st.st_mode):
        raise OutputError(f"{what}: {path} is a symbolic link; refusing to replace it")
    if stat.S_ISDIR(st.st_mode):
        raise OutputError(f"{what}: {path} is a directory; give a file name")
    if not stat.S_ISREG(st.st_mode):
        raise OutputError(
            f"{what}: {path} exists and is not a regular file (a device, FIFO or socket); "
            "refusing to replace it"
        )


def _existing_ancestor(path: Path, what: str) -> Path:
    """The nearest existing ancestor of ``path``; OutputError unless it is a directory."""
    parent = path.parent
    while not os.path.lexists(parent) and parent != parent.parent:
        parent = parent.parent
    if not parent.is_dir():
        raise OutputError(f"{what}: cannot write {path}: {parent} is not a directory")
    return parent


def _probe_writable(directory: Path, path: Path, what: str) -> None:
    """OutputError unless a file can be created (and removed) in ``directory``."""
    try:
        fd, probe = tempfile.mkstemp(prefix=".gdnplan-probe.", dir=directory)
    except OSError as e:
        raise OutputError(
            f"{what}: cannot write {path}: directory {directory} is not writable ({e.strerror})"
        ) from e
    os.close(fd)
    os.unlink(probe)


def check_output_dir(path: Path | str, what: str = "output") -> Path:
    """Check that files can be written in directory ``path`` (created later if missing).

    Raises:
        OutputError: ``path`` exists and is not a directory (or is a symlink to something else),
            an ancestor is not a directory, the directory that would hold it is read-only, or
            the system refuses the name (a component longer than the file system allows).
    """
    path = Path(path)
    try:
        exists = os.lstat(path) is not None
    except (FileNotFoundError, NotADirectoryError):  # the ancestors are checked below
        exists = False
    except (OSError, ValueError) as e:  # a name too long, a NUL byte
        why = e.strerror if isinstance(e, OSError) and e.strerror else str(e)
        raise OutputError(f"{what}: cannot write {path} ({why})") from e
    if exists:
        if not path.is_dir():
            raise OutputError(f"{what}: {path} exists and is not a directory")
        _probe_writable(path, path, what)
        return path
    _probe_writable(_existing_ancestor(path, what), path, what)
    return path


def check_output_path(
    path: Path | str, suffixes: Sequence[str] | None = None, what: str = "output"
) -> Path:
    """Check, before the work, that ``path`` can be written by :func:`atomic_path`.

    Args:
        path: the output file.
        suffixes: allowed suffixes (e.g. ``(".png",)``, compared case-insensitively); None
            accepts any.
        what: the option or field named in the error (``"--out"``).

    Returns:
        ``path`` as a Path.

    Raises:
        OutputError: a suffix not in ``suffixes``, an existing target that is not a regular file
            (directory, symlink, device, FIFO, socket), an ancestor that is not a directory, or
            a directory where no file can be created.
    """
    path = Path(path)
    if suffixes is not None and path.suffix.lower() not in suffixes:
        raise OutputError(
            f"{what}: {str(path)!r} is not a file name ending in {' or '.join(suffixes)}; "
            "give one with such a suffix"
        )
    _check_target(path, what)
    _probe_writable(_existing_ancestor(path, what), path, what)
    return path


def _umask() -> int:
    """The process umask, read without changing it where /proc allows."""
    try:
        for line in Path("/proc/self/status").read_text().splitlines():
            if line.startswith("Umask:"):
                return int(line.split()[1], 8)
    except OSError:
        pass
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


class _TerminatedError(SystemExit):
    """SIGTERM received while an atomic write was under way."""


@contextlib.contextmanager
def _sigterm_as_exception() -> Iterator[None]:
    """Within the block, SIGTERM raises SystemExit(143) (main thread, default handler only)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    if signal.getsignal(signal.SIGTERM) is not signal.SIG_DFL:
        yield
        return

    def handler(signum, frame):
        raise _TerminatedError(128 + signal.SIGTERM)

    signal.signal(signal.SIGTERM, handler)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, signal.SIG_DFL)


def _fsync(path: Path, directory: bool = False) -> None:
    fd = os.open(path, os.O_RDONLY | (os.O_DIRECTORY if directory else 0))
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


@contextlib.contextmanager
def atomic_path(path: Path | str, what: str = "output") -> Iterator[Path]:
    """Yield a temporary path beside ``path``; when the block ends normally it replaces ``path``.

    The temporary name ends with ``.tmp`` + the target's suffix (writers that infer the format
    from the name keep working). See the module docstring for the guarantees.

    Raises:
        OutputError: the target is not a regular file, or writing failed with an OSError
            (the temporary file is removed in every failure case).
    """
    path = Path(path)
    _check_target(path, what)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, name = tempfile.mkstemp(
            prefix=f".{path.name}.", suffix=f".tmp{path.suffix}", dir=path.parent
        )
    except OSError as e:
        raise OutputError(f"{what}: cannot write {path} ({e.strerror or e})") from e
    os.close(fd)
    tmp = Path(name)
    try:
        with _sigterm_as_exception():
            try:
                yield tmp
                _fsync(tmp)
                os.chmod(tmp, 0o666 & ~_umask())
                _check_target(path, what)  # still not a device, directory or symlink
                os.replace(tmp, path)
            except OutputError:
                raise
            except OSError as e:
                raise OutputError(f"{what}: writing {path} failed ({e.strerror or e})") from e
    finally:
        with contextlib.suppress(FileNotFoundError):
            tmp.unlink()
    with contextlib.suppress(OSError):
        _fsync(path.parent, directory=True)


def write_text(path: Path | str, text: str, what: str = "output") -> Path:
    """Write ``text`` (UTF-8) to ``path`` atomically; returns ``path``."""
    path = Path(path)
    with atomic_path(path, what) as tmp:
        tmp.write_text(text, encoding="utf-8")
    return path


__all__ = [
    "FIGURE_SUFFIXES",
    "MAX_INPUT_BYTES",
    "atomic_path",
    "check_input_file",
    "check_output_dir",
    "check_output_path",
    "read_input",
    "write_text",
]
