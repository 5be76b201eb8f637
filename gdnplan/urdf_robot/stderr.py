"""What C++ code (urdfdom, assimp, coal) prints on stderr, captured instead of shown."""

from __future__ import annotations

import contextlib
import os
import tempfile
from collections.abc import Iterator


@contextlib.contextmanager
def stderr_captured() -> Iterator[list[str]]:
    """Collect what C++ code (urdfdom) writes to file descriptor 2 into a list of lines."""
    lines: list[str] = []
    saved = os.dup(2)
    with tempfile.TemporaryFile(mode="w+") as tmp:
        os.dup2(tmp.fileno(), 2)
        try:
            yield lines
        finally:
            os.dup2(saved, 2)
            os.close(saved)
            tmp.seek(0)
            lines.extend(tmp.read().splitlines())
