"""Errors raised on bad input. Every message names the offending field and how to fix it."""

from __future__ import annotations

import difflib
from collections.abc import Iterable


class GdnplanError(Exception):
    """Base class of every error gdnplan raises on purpose (the CLI prints it and exits 2)."""


class UnknownNameError(GdnplanError, KeyError):
    """An unknown robot, scene, model or option name."""

    def __str__(self) -> str:  # KeyError would quote the message
        return str(self.args[0]) if self.args else ""


class InputError(GdnplanError, ValueError):
    """An array of the wrong shape, a NaN, a value outside its limits."""


SCHEMA_DOC = "docs/problem_file.md"  # the problem-file schema, every table and key


class ProblemFileError(GdnplanError, ValueError):
    """A malformed or inconsistent problem TOML file.

    Args:
        message: one line naming the table or key and the fix.
        schema: the error is about the file's tables and keys (an unknown or missing one):
            the message then ends with a pointer to the schema, ``(see docs/problem_file.md)``.
    """

    def __init__(self, message: str, *, schema: bool = False) -> None:
        super().__init__(f"{message} (see {SCHEMA_DOC})" if schema else message)


class InfeasibleProblemError(GdnplanError):
    """A problem no planner can solve as stated (start or goal in collision, goal out of reach)."""


class OutputError(GdnplanError):
    """An output path that cannot be written: an unknown suffix, a target that is not a regular
    file, a parent that is not a directory, a read-only directory, a full disk."""


def numba_environment_error(error: ValueError) -> InputError:
    """The InputError of numba refusing its environment variables at import (e.g.
    ``NUMBA_NUM_THREADS=0``: "Number of threads specified must be > 0."), which was an
    internal error of the first learned model loaded."""
    return InputError(
        f"NUMBA_NUM_THREADS / NUMBA_* environment: numba refuses it ({error}); unset the "
        "variable or give a valid value (NUMBA_NUM_THREADS: a positive integer)"
    )


def did_you_mean(name: object, choices: Iterable[str]) -> str:
    """`` (did you mean 'x'?)`` naming the choice closest to ``name`` (difflib, ratio ≥ 0.6),
    else ""; for the messages of unknown names and keys. A name that is no string, or longer
    than any sensible name (200 characters), gets no suggestion."""
    if not isinstance(name, str) or len(name) > 200:
        return ""
    close = difflib.get_close_matches(name, [c for c in choices if isinstance(c, str)], n=1)
    return f" (did you mean {close[0]!r}?)" if close else ""
