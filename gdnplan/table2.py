"""The paper's Table II: trajectory optimisation with each collision model, side by side.

Three settings of 20 random reaching problems each (the paper's):

* ``b``: the 2-DoF arm in environment (b) — a random scene per problem;
* ``d``: the 7-DoF arm in environment (d) — a random scene per problem;
* ``fetch``: the UR5e reaching into a random storage layout (fetch seeds 1 …, never a layout of
  the ur5e training data) with the open gripper, q_home → q_grasp.

For (b) and (d) start and goal are uniform random configurations with coal clearance ≥ margin
+ 3 cm whose straight joint-space line is *not* certified free (otherwise there is nothing to
optimise), that pass :class:`~gdnplan.trajopt.Problem`'s feasibility checks and that are known
to be solvable: RRT-Connect on coal connects them within ``SELECT_ITERATIONS`` extensions (a
random pair may lie in different components of the free space — the square can wall off the
2-DoF arm — and then every method fails; such pairs say nothing about the collision models).
That test is an iteration cap, not a time limit, so the problems do not depend on the
machine's speed or load. Each problem is
solved with every collision model — coal (exact), GraphDistNet (``weights/<env>``), ClearanceNet
(``weights/clearancenet_<env>``) and DiffCo (trained on the problem's own scene with coal labels,
its smooth fitted surrogate as the constraint) — by Ipopt and by the paper's Adam optimiser.
Success is never the solver's word: the path must pass the certified coal check and reach the
goal (:func:`gdnplan.trajopt.plan`). Reported per setting, model and solver: success rate,
mean and median wall time, and mean path cost Σ_t ‖q_{t+1} − q_t‖² over the problems *every*
row of the setting solved (the paper's rule), beside the paper's numbers.

Modules: the records, rows and the paper's figures in :mod:`gdnplan.table2_records`, the
markdown and its files in :mod:`gdnplan.table2_text`; this module draws the problems and solves
them, and re-exports their names.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterable
from pathlib import Path

import numpy as np
from tqdm import tqdm

from .assets import WEIGHTS_DIR
from .ccd import verify_path
from .distance import signed_distance
from .errors import InfeasibleProblemError, InputError
from .limits import floor_text
from .models import CoalModel, DistanceModel, load_model
from .rrt import rrt_connect
from .scene import make_scene
from .table2_records import METHODS, PAPER, SETTINGS, SOLVERS, Record, Row, summarize
from .table2_text import NOTES, markdown, write
from .trajopt import Plan, PlanConfig, Problem, TrajoptOptions, plan, straight_line
from .trajopt.config import with_optimizer

MARGIN = {"b": 0.02, "d": 0.02, "fetch": 0.01}  # constraint d ≥ margin (m)
WAYPOINTS = {"b": 20, "d": 20, "fetch": 30}  # the paper: 20 waypoints
DIFFCO_SAMPLES = {"b": 3000, "d": 5000, "fetch": 3000}  # coal-labelled training configurations
WEIGHTS_ENV = {"b": "b", "d": "d", "fetch": "ur5e"}
SELECT_ITERATIONS = 5000  # RRT-Connect extensions that prove a (b)/(d) problem solvable
SELECT_TIME = 3600.0  # s: only a guard; the iteration cap decides (module docstring)


def reaching_problems(setting: str, n: int = 20, seed: int = 0) -> list[Problem]:
    """The n problems of ``setting`` (deterministic in ``seed``); see the module docstring."""
    if setting == "fetch":
        return [_fetch_problem(s) for s in range(seed + 1, seed + 1 + n)]
    if setting not in ("b", "d"):
        raise InputError(f"setting: unknown {setting!r}; choose from {SETTINGS}")
    rng = np.random.default_rng(seed)
    margin, clearance = MARGIN[setting], 0.03
    out = []
    while len(out) < n:
        scene = make_scene(setting, seed=int(rng.integers(2**31)))
        q = scene.robot.sample(2, seed=int(rng.integers(2**31)))
        if np.any(signed_distance(scene, q) <= margin + clearance):
            continue
        try:
            p = Problem(scene, q[0], q[1], waypoints=WAYPOINTS[setting], margin=margin)
        except InfeasibleProblemError:
            continue
        if verify_path(scene, straight_line(q[0], q[1], p.waypoints), margin=margin)[0]:
            continue
        rrt = rrt_connect(
            scene,
            q[0],
            q[1],
            margin,
            seed=0,
            max_iterations=SELECT_ITERATIONS,
            time_limit=SELECT_TIME,
        )
        if rrt.success:
            out.append(p)
    return out


def _fetch_problem(seed: int) -> Problem:
    scene = make_scene("fetch", seed=seed, gripper="open")
    return Problem(
        scene,
        scene.info["q_home"],
        scene.info["q_grasp"],
        waypoints=WAYPOINTS["fetch"],
        margin=MARGIN["fetch"],
    )


ModelFactory = Callable[[Problem], DistanceModel]


def model_factory(method: str, setting: str, weights_dir: Path = WEIGHTS_DIR) -> ModelFactory:
    """problem → the collision model of ``method`` for that problem.

    Raises InputError when the method's weights are not shipped for the setting (there is no
    ClearanceNet for the fetch layouts: its fixed-size input encodes environments (a)–(e)).
    """
    if method == "coal":
        return lambda problem: CoalModel()
    if method == "DiffCo":
        from .models.diffco import DiffCo

        return lambda problem: DiffCo.train(problem.scene, n=DIFFCO_SAMPLES[setting]).fitted()
    stem = {"GraphDistNet": "", "ClearanceNet": "clearancenet_"}.get(method)
    if stem is None:
        raise InputError(f"method: unknown {method!r}; choose from {METHODS}")
    path = weights_dir / f"{stem}{WEIGHTS_ENV[setting]}.safetensors"
    if not path.exists():
        raise InputError(
            f"{method} for setting {setting!r}: no weights {path.name} in {weights_dir.name}/"
        )
    model = load_model(path)
    return lambda problem: model


def run_setting(
    setting: str,
    problems: list[Problem],
    methods: Iterable[str] = METHODS,
    solvers: Iterable[str] = SOLVERS,
    options: PlanConfig | TrajoptOptions | None = None,
    weights_dir: Path = WEIGHTS_DIR,
    log: Callable[[str], None] = print,
    first: int = 0,
) -> tuple[list[Record], list[str]]:
    """Solve every problem with every available method and solver.

    ``problems[0]`` is problem number ``first`` of the setting (to split a run over processes).

    Returns:
        The records, and one line per method skipped (no weights) saying why.
    """
    records, skipped, solvers = [], [], tuple(solvers)
    factories = {}
    for method in methods:
        try:
            factories[method] = model_factory(method, setting, weights_dir)
        except InputError as e:
            skipped.append(str(e))
    bar = tqdm(problems, desc=f"table2 {setting}", mininterval=5)
    for i, problem in enumerate(bar, start=first):
        for method, factory in factories.items():
            start = time.perf_counter()
            model = factory(problem)  # DiffCo trains here, once for both solvers
            prep = time.perf_counter() - start if method == "DiffCo" else 0.0
            for solver in solvers:
                old = isinstance(options, TrajoptOptions)  # deprecated
                base = options.to_config(solver) if old else options or PlanConfig()
                r = plan(problem, collision=model, solver=with_optimizer(base, solver), seed=i)
                records.append(_record(setting, method, solver, i, r, prep))
                log(
                    f"{setting} #{i} {method}+{solver}: {'ok' if r.success else 'FAIL'} "
                    f"{floor_text(r.min_distance)} m {r.solve_time:.2f} s {r.status}"
                )
    return records, skipped


def _record(setting: str, method: str, solver: str, i: int, r: Plan, prep: float) -> Record:
    return Record(
        setting,
        method,
        solver,
        i,
        bool(r.success),
        float(r.solve_time),
        float(prep),
        float(r.path_cost),
        float(r.min_distance),
        r.status,
        r.reason,
    )


__all__ = [
    "METHODS",
    "NOTES",
    "PAPER",
    "SETTINGS",
    "SOLVERS",
    "Record",
    "Row",
    "markdown",
    "model_factory",
    "reaching_problems",
    "run_setting",
    "summarize",
    "write",
]
