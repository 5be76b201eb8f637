"""Errors raised on bad input. Every message names the offending field and how to fix it."""

from __future__ import annotations


class GdnplanError(Exception):
    """Base class of every error gdnplan raises on purpose (the CLI prints it and exits 2)."""


class UnknownNameError(GdnplanError, KeyError):
    """An unknown robot, scene, model or option name."""

    def __str__(self) -> str:  # KeyError would quote the message
        return str(self.args[0]) if self.args else ""


class InputError(GdnplanError, ValueError):
    """An array of the wrong shape, a NaN, a value outside its limits."""


class ProblemFileError(GdnplanError, ValueError):
    """A malformed or inconsistent problem TOML file."""


class InfeasibleProblemError(GdnplanError):
    """A problem no planner can solve as stated (start or goal in collision, goal out of reach)."""


class OutputError(GdnplanError):
    """An output path that cannot be written: an unknown suffix, a target that is not a regular
    file, a parent that is not a directory, a read-only directory, a full disk."""
