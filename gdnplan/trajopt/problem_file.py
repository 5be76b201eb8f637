"""Problem files: reading the TOML, the keys of each table, the planner tables (``[seed]``,
``[refine]``, ``[ipopt]``, ``[adam]``, and the deprecated ``[solver]``) as a
:class:`~gdnplan.trajopt.config.PlanConfig`, and the checked vectors they hold.

:func:`problem_tables` is the one parser of a problem file's tables: :meth:`Problem.from_config`
and the CLI's ``show`` both use it. ``docs/problem_file.md`` documents every key;
``tests/test_problem_file_docs.py`` checks it against the key sets here.
"""

from __future__ import annotations

import os
import tomllib
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..arm3d.scene3d import Scene3D
from ..arm3d.scene_file3d import scene3d_from_config
from ..assets import problem_file
from ..errors import InputError, ProblemFileError
from ..files import read_input
from ..limits import IPOPT_OPTIONS, is_number, shown
from ..scene import Scene, no_unknown_keys, scene_from_config
from .config import CONFIG_TABLES, AdamConfig, IpoptConfig, PlanConfig, config_keys
from .options import OLD_KEYS, REMOVED, SOLVER_KEYS

# problem-file keys (docs/problem_file.md documents each; tests/test_problem_file_docs.py checks);
# [robot], [scene], [[obstacles]]: scene.ROBOT_KEYS etc.; [seed] … [adam]: CONFIG_KEYS;
# [solver] (deprecated): SOLVER_KEYS
PLAN_TABLES = tuple(CONFIG_TABLES)  # seed, refine, ipopt, adam
TOP_KEYS = frozenset(
    {"robot", "scene", "obstacles", "start", "goal", "options", "solver", *PLAN_TABLES}
)
START_KEYS = frozenset({"q"})
GOAL_KEYS = frozenset({"q", "position"})  # exactly one of them
# a file with a [scene3d] table is a 3-D problem (docs/problem_file_3d.md): [robot] names a
# 3-D robot, [scene3d] holds the obstacles, the goal is a joint vector
TOP_KEYS_3D = frozenset({"robot", "scene3d", "start", "goal", "options", "solver", *PLAN_TABLES})
GOAL_KEYS_3D = frozenset({"q", "pose"})  # exactly one of them
OPTION_KEYS = frozenset(
    {"waypoints", "margin", "clearance", "max_step", "goal_tolerance", "lower", "upper"}
)
CONFIG_KEYS = {table: config_keys(kind) for table, kind in CONFIG_TABLES.items()}
HOME = {key: table for table, keys in CONFIG_KEYS.items() for key in keys}  # key -> its table
HOME["interpolated"] = "ipopt] or [adam"  # in both


def read_problem_file(path: str | Path) -> dict:
    """The parsed TOML mapping of a problem file (UTF-8, with or without a byte-order mark);
    ProblemFileError when it cannot be read, is no regular file of at most
    ``MAX_INPUT_BYTES`` (:func:`gdnplan.files.read_input`), is not UTF-8 text, is malformed,
    holds an integer too long to read or nests deeper than Python's parser can follow.

    ``path``: a file, or the name of a shipped problem (``"fetch_reach"``).
    """
    path = problem_file(path)
    try:
        # utf-8-sig: a byte-order mark (Windows editors write one) is read, not refused as
        # "Invalid statement (at line 1, column 1)", as in point files
        return tomllib.loads(read_input(path, "problem file").decode("utf-8-sig"))
    except InputError as e:  # missing, a directory, a FIFO or device, larger than 256 MiB
        raise ProblemFileError(str(e)) from e
    except UnicodeDecodeError as e:
        raise ProblemFileError(f"{path}: not UTF-8 text (byte {e.start}); save it as UTF-8") from e
    except tomllib.TOMLDecodeError as e:
        raise ProblemFileError(f"{path}: malformed TOML: {e}") from e
    except ValueError as e:  # an integer of more digits than Python converts (sys.int_info)
        raise ProblemFileError(f"{path}: a number too long to read ({e}); shorten it") from e
    except RecursionError as e:
        raise ProblemFileError(f"{path}: arrays or tables nest too deeply; flatten them") from e


@dataclass(frozen=True)
class ProblemTables:
    """A problem file's tables, checked but not yet a Problem: the scene, the raw ``[start] q``
    and ``[goal]`` (None when absent), the ``[options]`` and the planner settings."""

    scene: Scene | Scene3D
    start: object
    goal: dict | None
    options: dict
    solver: PlanConfig | None


def problem_tables(cfg: dict, base_dir=None, require_goal: bool = True) -> ProblemTables:
    """Check every table of a parsed problem file and build its scene and planner settings;
    ``require_goal``: a ``[start] q`` and a ``[goal]`` must be there (False: a scene-only file,
    as ``gdnplan show`` draws). A file with a ``[scene3d]`` table is a 3-D problem
    (:func:`gdnplan.arm3d.scene_file3d.scene3d_from_config`). ProblemFileError names any bad
    field."""
    if not isinstance(cfg, dict):  # None raised TypeError, a list "[start]: missing table"
        raise ProblemFileError(
            f"problem: expected a table of tables (a parsed TOML file), got {type(cfg).__name__}"
        )
    if base_dir is not None and not isinstance(base_dir, (str, os.PathLike)):
        raise ProblemFileError(f"base_dir: expected a folder path, got {type(base_dir).__name__}")
    three_d = "scene3d" in cfg
    _no_unknown(cfg, TOP_KEYS_3D if three_d else TOP_KEYS, "top level")
    goal_keys = GOAL_KEYS_3D if three_d else GOAL_KEYS
    for key, keys in (("start", START_KEYS), ("goal", goal_keys)):
        if key not in cfg and not require_goal:
            continue
        if key not in cfg:
            raise ProblemFileError(f"[{key}]: missing table", schema=True)
        if not isinstance(cfg[key], dict):
            raise ProblemFileError(f"[{key}]: expected a table, got {shown(cfg[key])}")
        _no_unknown(cfg[key], keys, f"[{key}]")
    options = cfg.get("options", {})
    if not isinstance(options, dict):
        raise ProblemFileError("[options]: expected a table")
    _no_unknown(options, OPTION_KEYS, "[options]")
    solver = plan_config_from_tables(cfg)
    if three_d:
        scene = scene3d_from_config(cfg, base_dir)
    else:
        try:
            scene = scene_from_config(cfg, base_dir)
        except TypeError as e:
            raise ProblemFileError(f"[robot]/[scene]: unsupported option ({e})") from e
    goal = cfg.get("goal")
    if three_d and goal is not None and ("q" in goal) == ("pose" in goal):
        raise ProblemFileError(
            "[goal]: give exactly one of q = [...] or pose = {position = [x, y, z], ...}",
            schema=True,
        )
    if not three_d and goal is not None and ("q" in goal) == ("position" in goal):
        raise ProblemFileError(
            "[goal]: give exactly one of q = [...] or position = [x, y]", schema=True
        )
    start = cfg.get("start")
    if start is not None and "q" not in start:
        raise ProblemFileError("[start] q: missing; give the start joint angles", schema=True)
    return ProblemTables(scene, None if start is None else start.get("q"), goal, options, solver)


def problem_start(cfg: dict, scene: Scene) -> np.ndarray | None:
    """The checked ``[start] q`` of a parsed problem file (None when absent), for drawing;
    the planner tables are checked too (what ``plan`` rejects, ``show`` rejects)."""
    plan_config_from_tables(cfg)
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


def plan_config_from_tables(cfg: dict) -> PlanConfig | None:
    """The PlanConfig of a file's ``[seed]``, ``[refine]``, ``[ipopt]`` and ``[adam]`` tables
    (None when it has none); an ``[adam]`` table picks the Adam optimiser (at most one of
    ``[ipopt]`` and ``[adam]``). A deprecated ``[solver]`` table is mapped key by key onto
    them (:data:`~gdnplan.trajopt.options.OLD_KEYS`) with a FutureWarning (shown by default)."""
    tables = {t: _table(cfg[t], t) for t in PLAN_TABLES if t in cfg}
    if "solver" in cfg:
        _merge_old_solver(_table(cfg["solver"], "solver"), tables)
    if not tables:
        return None
    if "ipopt" in tables and "adam" in tables:
        raise ProblemFileError(
            "[ipopt], [adam]: give at most one; the table picks the optimiser the problem is "
            "set up for (gdnplan plan --solver picks another)"
        )
    for table, values in tables.items():
        for key, value in values.items():
            _typed(value, getattr(CONFIG_TABLES[table](), key), f"[{table}] {key}")
    optimizer = AdamConfig if "adam" in tables else IpoptConfig
    built = {}
    for table, name in (("seed", "seed"), ("refine", "refine"), ("ipopt", None), ("adam", None)):
        if table in tables or (name is None and CONFIG_TABLES[table] is optimizer):
            try:
                built[name or "optimizer"] = CONFIG_TABLES[table](**tables.get(table, {}))
            except InputError as e:
                raise ProblemFileError(f"[{table}] {e}") from e
    return PlanConfig(**built)


def _table(value, name: str) -> dict:
    """A planner table's keys, each checked to belong here (naming the table it belongs in)."""
    if not isinstance(value, dict):
        raise ProblemFileError(f"[{name}]: expected a table")
    allowed = SOLVER_KEYS if name == "solver" else CONFIG_KEYS[name]
    for key in value:
        if key not in allowed and key in HOME:
            raise ProblemFileError(
                f"[{name}] {key}: not a [{name}] key; it belongs in [{HOME[key]}]"
            )
    _no_unknown(value, allowed, f"[{name}]")
    options = value.get("options" if name == "ipopt" else "ipopt")
    if name in ("ipopt", "solver") and isinstance(options, dict):
        where = "[ipopt.options]" if name == "ipopt" else "[solver.ipopt]"
        _no_unknown(options, IPOPT_OPTIONS.keys(), where)
    return dict(value)


def _merge_old_solver(old: dict, tables: dict[str, dict]) -> None:
    """Map a deprecated ``[solver]`` table's keys onto the new tables (warns once)."""
    homes = []
    to_adam = any(k.startswith("adam_") for k in old) and not any(
        OLD_KEYS[k] is not None and OLD_KEYS[k][0] == "ipopt" and k != "interpolated" for k in old
    )
    for key, value in old.items():
        home = OLD_KEYS[key]
        if home is None:
            raise ProblemFileError(f"[solver] {key}: {REMOVED}; delete the line")
        table, new = ("adam", "interpolated") if key == "interpolated" and to_adam else home
        default = getattr(CONFIG_TABLES[table](), new)
        _typed(value, default, f"[solver] {key}")
        try:
            CONFIG_TABLES[table](**{new: value})
        except InputError as e:
            raise ProblemFileError(f"[solver] {key} (now [{table}] {new}): {e}") from e
        if new in tables.get(table, {}):
            raise ProblemFileError(f"[solver] {key}: also set as [{table}] {new}; keep that one")
        tables.setdefault(table, {})[new] = value
        homes.append(f"{key} → [{table}] {new}")
    warnings.warn(
        "problem file: the [solver] table is deprecated; "
        + (f"move its keys: {', '.join(homes)}" if homes else "it is empty: delete it"),
        FutureWarning,  # for the file's author (Python shows it by default), not a developer
        stacklevel=4,
    )


def _typed(value, default, where: str) -> None:
    """ProblemFileError unless ``value`` has the TOML type of ``default`` (None: any; the
    config's own check judges it)."""
    if default is None:
        return
    kind = (int, float) if type(default) is float else type(default)
    kind = list if kind is tuple else kind
    if not isinstance(value, kind) or isinstance(value, bool) != isinstance(default, bool):
        names = {float: "a number", int: "an integer", bool: "true or false", dict: "a table"}
        names[tuple] = "a list"
        wanted = names.get(type(default), f"a {type(default).__name__}")
        raise ProblemFileError(f"{where}: expected {wanted}, got {shown(value)}")


_no_unknown = no_unknown_keys  # the check of every table's keys (the CLI uses it too)


def _vector(value, n: int, name: str) -> np.ndarray:
    """A finite float (n,) vector or InputError naming the field (no strings, no booleans)."""
    items = value.tolist() if isinstance(value, np.ndarray) else value
    if not isinstance(items, (list, tuple)) or not all(is_number(x) for x in items):
        raise InputError(f"{name}: expected a list of {n} numbers, got {shown(value)}")
    try:
        v = np.asarray(value, dtype=float)
    except (TypeError, ValueError) as e:
        raise InputError(f"{name}: expected {n} numbers, got {shown(value)}") from e
    if v.shape != (n,):
        raise InputError(f"{name}: expected {n} numbers, got shape {v.shape}")
    if not np.all(np.isfinite(v)):
        raise InputError(f"{name}: contains NaN or infinite values")
    v.setflags(write=False)
    return v


__all__ = [
    "CONFIG_KEYS",
    "GOAL_KEYS",
    "GOAL_KEYS_3D",
    "OPTION_KEYS",
    "SOLVER_KEYS",
    "START_KEYS",
    "TOP_KEYS",
    "TOP_KEYS_3D",
    "ProblemTables",
    "plan_config_from_tables",
    "problem_start",
    "problem_tables",
    "read_problem_file",
]
