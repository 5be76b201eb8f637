"""Problem files: reading the TOML, the keys of each table, the ``[solver]`` table as
:class:`~gdnplan.trajopt.TrajoptOptions`, and the checked vectors they hold.

``docs/problem_file.md`` documents every key; ``tests/test_problem_file_docs.py`` checks it
against the key sets here.
"""

from __future__ import annotations

import tomllib
from dataclasses import replace
from pathlib import Path

import numpy as np

from ..assets import problem_file
from ..errors import InputError, ProblemFileError
from ..limits import IPOPT_OPTIONS, is_number
from ..scene import Scene, no_unknown_keys
from .options import SOLVER_KEYS, TrajoptOptions

# problem-file keys (docs/problem_file.md documents each; tests/test_problem_file_docs.py checks);
# [robot], [scene], [[obstacles]]: scene.ROBOT_KEYS etc.; [solver]: SOLVER_KEYS
TOP_KEYS = frozenset({"robot", "scene", "obstacles", "start", "goal", "options", "solver"})
START_KEYS = frozenset({"q"})
GOAL_KEYS = frozenset({"q", "position"})  # exactly one of them
OPTION_KEYS = frozenset(
    {"waypoints", "margin", "clearance", "max_step", "goal_tolerance", "lower", "upper"}
)


def read_problem_file(path: str | Path) -> dict:
    """The parsed TOML mapping of a problem file; ProblemFileError when it cannot be read, is
    not UTF-8 text, is malformed or nests deeper than Python's parser can follow.

    ``path``: a file, or the name of a shipped problem (``"fetch_reach"``).
    """
    path = problem_file(path)
    try:
        return tomllib.loads(path.read_text(encoding="utf-8"))
    except OSError as e:
        raise ProblemFileError(f"{path}: cannot read the problem file ({e.strerror})") from e
    except UnicodeDecodeError as e:
        raise ProblemFileError(f"{path}: not UTF-8 text (byte {e.start}); save it as UTF-8") from e
    except tomllib.TOMLDecodeError as e:
        raise ProblemFileError(f"{path}: malformed TOML: {e}") from e
    except RecursionError as e:
        raise ProblemFileError(f"{path}: arrays or tables nest too deeply; flatten them") from e


def problem_start(cfg: dict, scene: Scene) -> np.ndarray | None:
    """The checked ``[start] q`` of a parsed problem file (None when absent), for drawing;
    the ``[solver]`` table is checked too (what ``plan`` rejects, ``show`` rejects)."""
    _solver_options(cfg.get("solver"))
    start = cfg.get("start")
    if start is None:
        return None
    if not isinstance(start, dict):
        raise ProblemFileError("[start]: expected a table with q = [...]")
    if "q" not in start:
        return None
    try:
        return _vector(start["q"], scene.robot.dof, "start.q")
    except InputError as e:
        raise ProblemFileError(str(e)) from e


def _solver_options(table: dict | None) -> TrajoptOptions | None:
    """TrajoptOptions from a problem file's ``[solver]`` table (None when absent)."""
    if table is None:
        return None
    if not isinstance(table, dict):
        raise ProblemFileError("[solver]: expected a table")
    _no_unknown(table, SOLVER_KEYS, "[solver]")
    if isinstance(table.get("ipopt"), dict):
        _no_unknown(table["ipopt"], IPOPT_OPTIONS.keys(), "[solver.ipopt]")
    defaults = TrajoptOptions()
    for key, value in table.items():
        default = getattr(defaults, key)  # None: int or bool settings with an automatic choice
        kind = (int, float) if type(default) is float else type(default)
        if default is not None and (
            not isinstance(value, kind) or isinstance(value, bool) != isinstance(default, bool)
        ):
            names = {float: "a number", int: "an integer", bool: "true or false", dict: "a table"}
            wanted = names.get(type(default), f"a {type(default).__name__}")
            raise ProblemFileError(f"[solver] {key}: expected {wanted}, got {value!r}")
    try:
        return replace(defaults, **table)
    except InputError as e:
        raise ProblemFileError(f"[solver] {e}") from e


_no_unknown = no_unknown_keys  # the check of every table's keys (cli.py uses it too)


def _vector(value, n: int, name: str) -> np.ndarray:
    """A finite float (n,) vector or InputError naming the field (no strings, no booleans)."""
    items = value.tolist() if isinstance(value, np.ndarray) else value
    if not isinstance(items, (list, tuple)) or not all(is_number(x) for x in items):
        raise InputError(f"{name}: expected a list of {n} numbers, got {value!r}")
    try:
        v = np.asarray(value, dtype=float)
    except (TypeError, ValueError) as e:
        raise InputError(f"{name}: expected {n} numbers, got {value!r}") from e
    if v.shape != (n,):
        raise InputError(f"{name}: expected {n} numbers, got shape {v.shape}")
    if not np.all(np.isfinite(v)):
        raise InputError(f"{name}: contains NaN or infinite values")
    v.setflags(write=False)
    return v


__all__ = [
    "GOAL_KEYS",
    "OPTION_KEYS",
    "SOLVER_KEYS",
    "START_KEYS",
    "TOP_KEYS",
    "problem_start",
    "read_problem_file",
]
