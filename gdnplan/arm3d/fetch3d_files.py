"""Problem files of the 3-D fetch's planned stages: one self-contained TOML file per stage.

A file holds everything its stage's planning problems need, so it does not depend on how a
seed's random draws went::

    [fetch3d]
    stage = "bring_out"            # approach, reach_in, bring_out or retreat
    gripper = "holding"            # the scene: "open" (stick an obstacle) or "holding" it
    placement = [0.62, -0.2, 0.0]  # the storage's front-face centre x, y (m) and yaw (rad)
    knots = [[...], ...]           # configurations the stage passes between start and goal

    [fetch3d.storage]              # every field of Storage3D (m)
    depth = 0.36 ...

    [start]  q = [...]  (6 joint angles, rad)
    [goal]   q = [...]
    [options] waypoints, margin (m)
    [seed], [refine], [ipopt], [adam]: the planner tables of planar problem files

:func:`read_stage_problems` rebuilds the scene (:func:`~gdnplan.arm3d.fetch3d_scene.fetch3d_scenes`)
and returns the stage's :class:`~gdnplan.trajopt.Problem` s, one per piece start → knots →
goal, as :func:`gdnplan.arm3d.fetch3d.stage_problems` builds them. Any bad field is a one-line
:class:`~gdnplan.errors.ProblemFileError` naming it.
"""

from __future__ import annotations

import dataclasses
import itertools
import math
from pathlib import Path

import numpy as np

from ..errors import GdnplanError, ProblemFileError
from ..files import check_output_dir
from ..trajopt import Problem
from ..trajopt.problem_file import plan_config_from_tables, read_problem_file
from .fetch3d import MARGIN, PLANNED, STAGE_SOLVERS, WAYPOINTS, knots
from .fetch3d_scene import Fetch3D, fetch3d_scenes
from .storage3d import Storage3D, check_placement

TOP_KEYS = {"fetch3d", "start", "goal", "options", "seed", "refine", "ipopt", "adam"}
FETCH_KEYS = {"stage", "gripper", "placement", "knots", "storage"}
STORAGE_FIELDS = tuple(f.name for f in dataclasses.fields(Storage3D))


def _num(x: float) -> str:
    return repr(float(x))


def _vec(q) -> str:
    return "[" + ", ".join(_num(v) for v in np.asarray(q, float)) + "]"


def stage_file_text(fetch: Fetch3D, stage: str, margin: float = MARGIN) -> str:
    """The TOML text of one planned stage's problem file (module doc)."""
    state, start, goal = PLANNED[stage]
    inner = knots(fetch, stage)[1:-1]
    p = fetch.placement
    lines = [
        f"# gdnplan 3-D fetch, stage {stage} (fetch seed {fetch.seed}): the UR5e's six joints,",
        "# coal distances; written by gdnplan.arm3d.fetch3d_files (read_stage_problems)",
        "[fetch3d]",
        f'stage = "{stage}"',
        f'gripper = "{state}"',
        f"placement = {_vec([p.x, p.y, p.yaw])}",
        "knots = [" + ", ".join(_vec(k) for k in inner) + "]",
        "",
        "[fetch3d.storage]",
        *(f"{f} = {_num(getattr(fetch.storage, f))}" for f in STORAGE_FIELDS),
        "",
        "[start]",
        f"q = {_vec(fetch.q[start])}",
        "",
        "[goal]",
        f"q = {_vec(fetch.q[goal])}",
        "",
        "[options]",
        f"waypoints = {WAYPOINTS}",
        f"margin = {_num(margin)}",
    ]
    solver = STAGE_SOLVERS.get(stage)
    if solver is not None:
        lines += ["", "[seed]", f"rrt_step = {_num(solver.seed.rrt_step)}"]
        lines.append(f"rrt_time = {_num(solver.seed.rrt_time)}")
    return "\n".join(lines) + "\n"


def write_stage_problems(fetch: Fetch3D, directory: str | Path) -> list[Path]:
    """Write ``fetch3d_<stage>.toml`` for every planned stage into ``directory`` (created)."""
    out = check_output_dir(directory, "--write-problems")
    out.mkdir(parents=True, exist_ok=True)
    paths = []
    for stage in PLANNED:
        path = out / f"fetch3d_{stage}.toml"
        path.write_text(stage_file_text(fetch, stage), encoding="utf-8")
        paths.append(path)
    return paths


def _vector(value, n: int, where: str) -> np.ndarray:
    ok = isinstance(value, list) and len(value) == n
    ok = ok and all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in value)
    if not ok or not all(math.isfinite(v) for v in value):
        raise ProblemFileError(f"{where}: expected {n} finite numbers, got {value!r}")
    return np.array(value, dtype=float)


def _unknown(table: dict, allowed: set, where: str) -> None:
    extra = sorted(set(table) - allowed)
    if extra:
        raise ProblemFileError(f"{where}: unknown key {extra[0]!r}; allowed: {sorted(allowed)}")


def _storage(table) -> Storage3D:
    if not isinstance(table, dict):
        raise ProblemFileError("[fetch3d.storage]: missing table of the storage's sizes")
    _unknown(table, set(STORAGE_FIELDS), "[fetch3d.storage]")
    values = {}
    for f in STORAGE_FIELDS:
        v = table.get(f)
        if not isinstance(v, (int, float)) or isinstance(v, bool) or not 0 < v < 10:
            raise ProblemFileError(
                f"[fetch3d.storage] {f}: expected a size in (0, 10) m, got {v!r}"
            )
        values[f] = float(v)
    return Storage3D(**values)


def read_stage_problems(path: str | Path) -> list[Problem]:
    """The planning problems of a stage's problem file (module doc), one per piece."""
    cfg = read_problem_file(Path(path))
    _unknown(cfg, TOP_KEYS, "top level")
    head = cfg.get("fetch3d")
    if not isinstance(head, dict):
        raise ProblemFileError("[fetch3d]: missing table (stage, gripper, placement, storage)")
    _unknown(head, FETCH_KEYS, "[fetch3d]")
    stage, gripper = head.get("stage"), head.get("gripper")
    if stage not in PLANNED:
        raise ProblemFileError(f"[fetch3d] stage: expected one of {list(PLANNED)}, got {stage!r}")
    if gripper != PLANNED[stage][0]:
        raise ProblemFileError(
            f'[fetch3d] gripper: stage {stage} moves "{PLANNED[stage][0]}", got {gripper!r}'
        )
    try:
        placement = check_placement(*_vector(head.get("placement"), 3, "[fetch3d] placement"))
    except GdnplanError as e:
        raise ProblemFileError(f"[fetch3d] placement: {e}") from e
    raw_knots = head.get("knots", [])
    if not isinstance(raw_knots, list):
        raise ProblemFileError("[fetch3d] knots: expected a list of joint vectors")
    inner = [_vector(k, 6, f"[fetch3d] knots[{i}]") for i, k in enumerate(raw_knots)]
    points = []
    for key in ("start", "goal"):
        table = cfg.get(key)
        if not isinstance(table, dict) or set(table) != {"q"}:
            raise ProblemFileError(f"[{key}]: expected a table with q = [6 joint angles]")
        points.append(_vector(table["q"], 6, f"[{key}] q"))
    options = cfg.get("options", {})
    if not isinstance(options, dict):
        raise ProblemFileError("[options]: expected a table")
    _unknown(options, {"waypoints", "margin"}, "[options]")
    scene = fetch3d_scenes(_storage(head.get("storage")), placement)[gripper]
    solver = plan_config_from_tables(cfg)
    chain = [points[0], *inner, points[1]]
    try:
        return [
            Problem(
                scene=scene,
                start=a,
                goal=b,
                waypoints=options.get("waypoints", WAYPOINTS),
                margin=options.get("margin", MARGIN),
                solver=solver,
            )
            for a, b in itertools.pairwise(chain)
        ]
    except GdnplanError as e:
        raise ProblemFileError(f"{Path(path).name}: {e}") from e


__all__ = ["read_stage_problems", "stage_file_text", "write_stage_problems"]
