"""The ``gdnplan`` command.

Exit status: 0 success; 1 planning failed (``plan``, ``fetch``); 2 bad input (a
:class:`~gdnplan.errors.GdnplanError` or a usage error: one line ``error: …`` naming the field and
the fix); 3 internal error (any other exception: one line ``error: internal error (Type: message);
rerun with --debug for the traceback``); 130 interrupted (Ctrl-C). ``gdnplan --debug <command> …``
prints the traceback of errors 2 and 3 as well.
"""

from __future__ import annotations

import json
import logging
import math
import sys
import traceback
from pathlib import Path
from typing import TYPE_CHECKING

import typer

try:  # typer ≥ 0.25 vendors click
    from typer._click import exceptions as click_exceptions
except ImportError:  # pragma: no cover - older typer depends on click
    from click import exceptions as click_exceptions

from .errors import GdnplanError, InfeasibleProblemError, InputError, ProblemFileError
from .files import FIGURE_SUFFIXES, check_output_dir, check_output_path, write_text

if TYPE_CHECKING:  # the commands import numpy and the library when they run: a fast --help
    import numpy as np

    from .scene import Scene

app = typer.Typer(
    help="Collision-free trajectory planning with GraphDistNet.",
    no_args_is_help=True,
    pretty_exceptions_enable=False,
    add_completion=False,
    rich_markup_mode=None,  # plain help: rendering it with rich costs ≈ 0.3 s per --help
    context_settings={"max_content_width": 100},  # up to 100 columns in a wide terminal
)


EXIT_FAILED, EXIT_INPUT, EXIT_INTERNAL, EXIT_INTERRUPTED = 1, 2, 3, 130
_DEBUG = {"on": False}  # set by ``--debug`` (the callback runs before the command)


def _print_version(value: bool) -> None:
    if value:
        from importlib.metadata import version

        typer.echo(f"gdnplan {version('gdnplan')}")
        raise typer.Exit()


@app.callback()
def _commands(
    debug: bool = typer.Option(False, "--debug", help="Print the traceback of any error."),
    version: bool = typer.Option(
        False, "--version", callback=_print_version, is_eager=True, help="Print the version."
    ),
) -> None:
    """Collision-free trajectory planning with GraphDistNet."""
    _DEBUG["on"] = debug


WEIGHTS_HELP = (
    "GraphDistNet weights: a shipped name (d, ur5e, …) or a .safetensors file "
    "(default: the shipped weights for the problem's robot and obstacles)."
)
PROBLEM_HELP = "A problem TOML file or a shipped problem's name (fetch_reach, planar7_d, …)."

QUIET_HELP = "No progress lines on stderr (warnings and errors only)."


class _StderrHandler(logging.StreamHandler):
    """Log records as bare lines on the ``sys.stderr`` of the moment (tests replace it)."""

    def __init__(self) -> None:
        super().__init__()
        self.setFormatter(logging.Formatter("%(message)s"))

    @property
    def stream(self):  # type: ignore[override]
        return sys.stderr

    @stream.setter
    def stream(self, value) -> None:  # StreamHandler.__init__ assigns one; stderr is used
        pass


def show_progress(on: bool) -> None:
    """Print the library's progress (the ``gdnplan`` logger's INFO lines: planner and fetch
    stages) to stderr, or only its warnings when ``on`` is False. Progress never goes to
    stdout, so ``--json`` output stays one JSON object. Undone by :func:`hide_progress`."""
    hide_progress()
    logger = logging.getLogger("gdnplan")
    logger.addHandler(_StderrHandler())
    logger.setLevel(logging.INFO if on else logging.WARNING)


def hide_progress() -> None:
    """Detach the handler of :func:`show_progress` (``run`` calls it as a command ends)."""
    logger = logging.getLogger("gdnplan")
    for old in [h for h in logger.handlers if isinstance(h, _StderrHandler)]:
        logger.removeHandler(old)
    logger.setLevel(logging.NOTSET)


THREADS_HELP = "torch threads for learned models (1 is fastest on a busy or 2-core CPU)."


def set_threads(threads: int, torch_global: bool = False) -> None:
    """The learned models' inference threads (:mod:`gdnplan.models.threads`) and, with
    ``torch_global`` (training, table runs), torch's own intra-op threads; InputError unless
    threads ≥ 1. Without ``torch_global`` torch is not imported (coal-only commands)."""
    if threads < 1:
        raise InputError(f"--threads: expected ≥ 1, got {threads}")
    from .models.threads import set_inference_threads

    set_inference_threads(threads)
    if torch_global:
        import torch

        torch.set_num_threads(threads)


def parse_vector(text: str, name: str) -> np.ndarray:
    """'0.1, -0.2, 0.3' -> array; raises InputError naming ``name``."""
    import numpy as np

    try:
        return np.array([float(v) for v in text.replace(",", " ").split()])
    except ValueError as e:
        raise InputError(f"{name}: expected numbers separated by commas, got {text!r}") from e


def scene_and_start(target: str, seed: int) -> tuple[Scene, np.ndarray | None]:
    """A scene from a problem file or shipped problem name (with its start q), or from a
    scene generator name."""
    from .assets import problem_names
    from .scene import make_scene, scene_names

    if (
        target.endswith(".toml")
        or target in problem_names()
        or (target not in scene_names() and Path(target).exists())
    ):
        return problem_scene_and_start(target)
    return make_scene(target, seed=seed), None


def problem_scene_and_start(path: str | Path) -> tuple[Scene, np.ndarray | None]:
    """The scene and ``[start] q`` of a problem file, checked as ``plan`` checks it (the one
    parser, :func:`gdnplan.trajopt.problem_tables`).

    A file with a ``[goal]`` passes every check of :meth:`Problem.from_config` except the
    feasibility ones (a start in collision is what ``show`` draws); a scene-only file (no
    ``[goal]``, ``[start]`` optional) the checks of its tables. ProblemFileError names the file.
    """
    from .assets import problem_file
    from .trajopt import Problem, _vector, problem_tables, read_problem_file

    cfg = read_problem_file(path)
    folder = problem_file(path).parent  # relative paths in the file ([robot] urdf) start here
    try:
        tables = problem_tables(cfg, base_dir=folder, require_goal="goal" in cfg)
        if tables.goal is not None:
            try:
                Problem.from_tables(tables)
            except InfeasibleProblemError:
                pass
        if tables.start is None:
            return tables.scene, None
        q = _vector(tables.start, tables.scene.robot.dof, "start.q")
        return tables.scene, check_limits(tables.scene.robot, q, "start.q")
    except GdnplanError as e:
        raise ProblemFileError(f"{path}: {e}") from e


def check_limits(robot, q: np.ndarray, name: str) -> np.ndarray:
    """``q`` (dof,) when it is within the robot's joint limits; InputError naming the joint."""
    from .robot import first_outside

    j = first_outside(q, robot.lower, robot.upper)
    if j is not None:
        raise InputError(
            f"{name}[{j}] = {q[j]:.4g} is outside the joint limits "
            f"[{robot.lower[j]:.4g}, {robot.upper[j]:.4g}] of {robot.name}"
        )
    return q


@app.command()
def show(
    target: str = typer.Argument(
        ..., help="A problem TOML file, a shipped problem's name or a scene name (a-e, fetch)."
    ),
    q: str = typer.Option(None, help="Joint angles 'q1,q2,...' (default: the problem's start)."),
    seed: int = typer.Option(0, min=0, help="Scene seed, for generated scenes."),
    out: Path = typer.Option(Path("scene.png"), help="Output PNG."),
) -> None:
    """Draw the robot, the obstacles and the witness segment of the signed distance."""
    from .viz import save_figure, scene_figure

    check_output_path(out, FIGURE_SUFFIXES, "--out")
    scene, start = scene_and_start(target, seed)
    if q is not None:
        config = check_limits(
            scene.robot, scene.robot.check_q(parse_vector(q, "--q"), "--q")[0], "--q"
        )
    else:
        config = start
    fig = scene_figure(scene, config)
    save_figure(fig, out)
    typer.echo(f"wrote {out}")


@app.command("plan")
def plan_command(
    problem_file: str = typer.Argument(..., help=PROBLEM_HELP),
    collision: str = typer.Option("graphdistnet", help="Collision model: graphdistnet or coal."),
    solver: str = typer.Option(
        None,
        help="ipopt (direct transcription) or adam (paper); default: the problem file's "
        "optimiser ([ipopt] or [adam] table), else ipopt.",
    ),
    weights: str = typer.Option(None, help=WEIGHTS_HELP),
    seed: int = typer.Option(0, min=0, help="Seed of the sampling-based initial guesses."),
    seeds: int = typer.Option(
        None,
        help="Seed paths refined (Ipopt), the cheapest certified path returned; default: the "
        "file's [seed] count, else 1 (with --time-budget: as many as fit).",
    ),
    time_budget: float = typer.Option(
        None,
        help="Wall-time budget (s): return the cheapest certified path found when it ends.",
    ),
    json_output: bool = typer.Option(False, "--json", help="Print one JSON object."),
    animate: Path = typer.Option(None, help="Write an animated GIF of the plan."),
    threads: int = typer.Option(1, help=THREADS_HELP),
    view3d: bool = typer.Option(False, "--view3d", help="3-D browser view (needs meshcat)."),
    max_acceleration: float = typer.Option(
        None, help="Joint acceleration limit (rad/s²) of the timing; default: velocity only."
    ),
    quiet: bool = typer.Option(False, "--quiet", "-q", help=QUIET_HELP),
) -> None:
    """Plan a collision-free trajectory; success is certified by a dense coal check.

    Exit status: 0 when the plan is certified, 1 when planning failed, 2 on bad input.
    """
    from .trajopt import Problem, plan

    show_progress(not quiet)
    if animate is not None:
        check_output_path(animate, (".gif",), "--animate")
    set_threads(threads)
    if view3d:  # fail before planning, not after
        from .viz3d import require_meshcat

        require_meshcat()
    problem = Problem.from_toml(problem_file)
    config = plan_flags_config(problem, solver, seeds, time_budget)
    result = plan(
        problem,
        collision=collision,
        solver=config,
        weights=weights,
        seed=seed,
        max_acceleration=max_acceleration,
    )
    if json_output:
        typer.echo(json.dumps(plan_summary(result, problem.scene.robot.joint_names)))
    else:
        verdict = "certified collision-free" if result.success else f"FAILED ({result.reason})"
        timed = "" if result.duration is None else f", duration {result.duration:.2f} s"
        typer.echo(
            f"{problem_file}: {verdict}; {clearance_text(result.min_distance)}, "
            f"solve time {result.solve_time:.2f} s, {result.iterations} iterations, "
            f"path cost {result.path_cost:.3f}{timed}"
        )
    if animate is not None:
        from .viz import animate_paths

        animate_paths(
            [(problem.scene, result.q)], animate, title=f"{Path(problem_file).name}: {collision}"
        )
        if not json_output:
            typer.echo(f"wrote {animate}")
    if view3d:
        from .viz3d import view_plan

        view_plan([(problem.scene, result.q)])
    if not result.success:
        raise typer.Exit(1)


def plan_flags_config(problem, solver: str | None, seeds: int | None, time_budget: float | None):
    """The PlanConfig of ``gdnplan plan``: the problem file's settings, with the optimiser
    ``--solver`` names (the file's settings for it when the file is set up for it, else its
    defaults) and ``--seeds`` / ``--time-budget`` over the file's ``[seed]`` table."""
    from dataclasses import replace

    from .trajopt import AdamConfig, PlanConfig
    from .trajopt.config import OPTIMIZERS, with_optimizer

    config = problem.solver or PlanConfig()
    if solver is not None:  # the named optimiser, with the file's settings when they are its
        if solver not in OPTIMIZERS:
            raise InputError(f"--solver: unknown {solver!r}; choose ipopt or adam")
        config = with_optimizer(config, solver)
    if seeds is not None and isinstance(config.optimizer, AdamConfig):
        raise InputError("--seeds: Adam starts from the straight line; seeds need --solver ipopt")
    try:
        count = config.seed.count if seeds is None else seeds
        budget = config.seed.time_budget if time_budget is None else time_budget
        config = replace(config, seed=replace(config.seed, count=count, time_budget=budget))
    except InputError as e:
        raise InputError(f"--seeds/--time-budget: {e}") from e
    return config


def clearance_text(lower_bound: float) -> str:
    """'certified clearance ≥ +0.0123 m', or 'clearance not proven' for a −inf bound."""
    if not math.isfinite(lower_bound):
        return "clearance not proven"
    return f"certified clearance ≥ {lower_bound:+.4f} m"


def json_number(x: float) -> float | None:
    """x as a JSON number; None (null) when not finite (JSON has no infinities)."""
    return float(x) if math.isfinite(x) else None


def plan_summary(result, joint_names: list[str]) -> dict:
    """JSON-ready summary of a Plan (min_distance: the proven lower bound, null if none;
    clearance: the clearance its certificate had to prove).

    ``t`` (s) is the time of each row of ``q`` (rad, columns in ``joint_names`` order), and
    ``timing`` its kind (:mod:`gdnplan.timing`); both null when the plan has no trajectory.
    """
    traj = result.trajectory
    import numpy as np

    return {
        "success": bool(result.success),
        "joint_names": list(joint_names),
        "q": np.asarray(result.q).tolist(),
        "t": None if traj is None else traj.times.tolist(),
        "duration": None if traj is None else traj.duration,
        "timing": None if traj is None else traj.kind,
        "min_distance": json_number(result.min_distance),
        "sampled_min_distance": json_number(result.sampled_min_distance),
        "clearance": float(result.clearance),
        "solve_time": float(result.solve_time),
        "iterations": int(result.iterations),
        "status": result.status,
        "reason": result.reason,
        "path_cost": float(result.path_cost),
        "seed": None if result.seed is None else result.seed.summary(),
        "attempts": int(result.attempts),
    }


reproduce_app = typer.Typer(
    help="Reproduce the paper's tables.", no_args_is_help=True, rich_markup_mode=None
)
app.add_typer(reproduce_app, name="reproduce")

EVAL_MODELS = ("coal", "diffco", "clearancenet", "graphdistnet")


@app.command("evaluate")
def evaluate_command(
    env: str = typer.Option("a", help="Environment a-e (its held-out split, seed 1)."),
    model: str = typer.Option("graphdistnet", help="coal | diffco | clearancenet | graphdistnet."),
    n: int = typer.Option(5000, min=1, max=5000, help="Held-out samples (time, MAE, AUC)."),
    n_grad: int = typer.Option(5000, min=1, help="Samples for the ACD (the first of the n)."),
) -> None:
    """Time, MAE, AUC and ACD of one collision model on held-out samples (Table I metrics)."""
    from . import evaluate as ev
    from .scene import make_scene

    if model not in EVAL_MODELS:
        raise InputError(f"--model: unknown {model!r}; choose one of {list(EVAL_MODELS)}")
    if env not in ev.ENVS:
        raise InputError(f"--env: expected one of {list(ev.ENVS)}, got {env!r}")
    if model == "coal":
        from .models import CoalModel

        chosen = CoalModel()
    elif model == "diffco":
        from .models.diffco import DiffCo

        chosen = DiffCo.train(make_scene(ev.DIFFCO_SOURCE.get(env, env)), n=3000)
    else:
        loader = ev.clearancenet_of_env if model == "clearancenet" else ev.graphdistnet_of_env
        chosen = loader(env)
        if chosen is None:
            raise InputError(f"--model: no {model} weights for env {env} in weights/")
    r = ev.evaluate_model(chosen, env, n, n_grad)
    mae = "N/A" if r.mae is None else f"{r.mae:.4f} m ({r.mae_reach:.4f} of reach)"
    acd = "N/A" if r.acd is None else f"{r.acd:.4f} ± {r.acd_se:.4f} over {r.n_grad}"
    typer.echo(
        f"{model} env {env}: n={r.n} time {r.seconds:.4f} s, MAE {mae}, AUC {r.auc:.4f}, ACD {acd}"
    )


@reproduce_app.command("table1")
def table1_command(
    fast: bool = typer.Option(False, "--fast", help="Few samples (CI); the full run is recorded."),
    envs: str = typer.Option("abcde", help="Environments to run, e.g. 'ab'."),
    out: Path = typer.Option(Path("results/table1.md"), help="Markdown output."),
    figures: Path = typer.Option(None, help="Directory for ROC/scatter PNGs (default: none)."),
    weights: Path = typer.Option(None, help="Directory of the trained weights (repo weights/)."),
) -> None:
    """The paper's Table I, ours beside the paper's numbers; markdown to stdout and ``out``."""
    import datetime
    import os
    import platform

    from . import evaluate as ev

    check_output_path(out, (".md",), "--out")
    if figures is not None:
        check_output_dir(figures, "--figures")
    weights = weights or ev.WEIGHTS_DIR
    if not envs or any(e not in ev.ENVS for e in envs):
        raise InputError(f"--envs: expected letters from 'abcde', got {envs!r}")
    results, missing, used = ev.table1(
        tuple(envs), fast, log=lambda m: typer.echo(m, err=True), weights_dir=weights
    )
    cpu = platform.processor() or platform.machine()
    header = [
        "# Table I reproduction" + (" (fast mode: few samples, not a result)" if fast else ""),
        "",
        f"- command: `gdnplan reproduce table1{' --fast' if fast else ''} --envs {envs}"
        f" --weights {weights}`",
        f"- date: {datetime.datetime.now().isoformat(timespec='seconds')}",
        f"- machine: {platform.node()}, {cpu}, {os.cpu_count()} cores (shared), "
        f"{platform.python_version()}",
        f"- missing weights: {', '.join(missing) if missing else 'none'}",
        f"- weights used (sha256 prefix, hashed at load): "
        f"{', '.join(f'{k}:{v}' for k, v in used.items()) or 'none'}",
        "",
        "",
    ]
    text = "\n".join(header) + ev.table1_markdown(results) + "\n"
    typer.echo(text)
    write_text(out, text, "--out")
    if figures is not None:
        for path in ev.table1_figures(results, figures):
            typer.echo(f"wrote {path}", err=True)


@reproduce_app.command("table2")
def table2_command(
    n: int = typer.Option(20, help="Problems per setting (the paper: 20)."),
    settings: str = typer.Option("b,d,fetch", help="Settings: b, d, fetch (comma-separated)."),
    methods: str = typer.Option(
        "GraphDistNet,ClearanceNet,DiffCo,coal", help="Collision models (comma-separated)."
    ),
    solvers: str = typer.Option("ipopt,adam", help="Optimisers: ipopt, adam (comma-separated)."),
    seed: int = typer.Option(0, min=0, help="Problem seed."),
    first: int = typer.Option(0, min=0, help="Run problems first … n − 1 only (split a run)."),
    threads: int = typer.Option(1, help=THREADS_HELP),
    out: Path = typer.Option(Path("results/table2.md"), help="Markdown output (+ .json)."),
    update: bool = typer.Option(
        False, help="Keep the rows of the earlier run at --out that this run does not redo."
    ),
) -> None:
    """The paper's Table II: every collision model × optimiser on random reaching problems."""
    from . import table2

    check_output_path(out, (".md",), "--out")
    check_output_path(out.with_suffix(".json"), (".json",), "--out")
    chosen = {
        name: [v.strip() for v in value.split(",") if v.strip()]
        for name, value in (("settings", settings), ("methods", methods), ("solvers", solvers))
    }
    allowed = {"settings": table2.SETTINGS, "methods": table2.METHODS, "solvers": table2.SOLVERS}
    for name, values in chosen.items():
        bad = [v for v in values if v not in allowed[name]]
        if bad or not values:
            raise InputError(f"--{name}: expected some of {allowed[name]}, got {bad or values}")
    if n < 1:
        raise InputError(f"--n: expected ≥ 1, got {n}")
    if first >= n:
        raise InputError(f"--first: expected a problem index below --n {n}, got {first}")
    set_threads(threads, torch_global=True)
    records, skipped = [], []
    for setting in chosen["settings"]:
        problems = table2.reaching_problems(setting, n, seed)[first:]
        got, why = table2.run_setting(
            setting,
            problems,
            chosen["methods"],
            chosen["solvers"],
            log=lambda m: typer.echo(m, err=True),
            first=first,
        )
        records += got
        skipped += why
    command = (
        f"gdnplan reproduce table2 --n {n} --settings {settings} --methods {methods} "
        f"--solvers {solvers} --seed {seed} --first {first} --threads {threads}"
        + (" --update" if update else "")
    )
    typer.echo(table2.write(records, skipped, command, out, update))


@app.command("fetch")
def fetch_command(
    seed: int = typer.Option(0, min=0, help="Fetch layout: 0 canonical, others random storages."),
    collision: str = typer.Option("graphdistnet", help="Collision model: graphdistnet or coal."),
    weights: str = typer.Option(None, help=WEIGHTS_HELP),
    animate: Path = typer.Option(None, help="Write an animated GIF of all stages."),
    json_output: bool = typer.Option(False, "--json", help="Print one JSON object."),
    threads: int = typer.Option(1, help=THREADS_HELP),
    view3d: bool = typer.Option(False, "--view3d", help="3-D browser view (needs meshcat)."),
    quiet: bool = typer.Option(False, "--quiet", "-q", help=QUIET_HELP),
) -> None:
    """The UR5e fetch: approach, reach in, grasp, lift, bring the stick out, retreat.

    Exit status: 0 when every stage is certified collision-free, 1 otherwise, 2 on bad input.
    """
    from .fetch import run_fetch

    show_progress(not quiet)
    if animate is not None:
        check_output_path(animate, (".gif",), "--animate")
    set_threads(threads)
    if view3d:  # fail before planning, not after
        from .viz3d import require_meshcat

        require_meshcat()
    stages = run_fetch(seed, collision=collision, weights=weights)
    ok = all(s.success for s in stages)
    if json_output:
        summary = {"seed": seed, "collision": collision, "success": ok}
        summary["stages"] = [s.summary() for s in stages]
        typer.echo(json.dumps(summary))
    else:
        for s in stages:
            how = "planned" if s.planned else "scripted"
            verdict = "certified" if s.success else f"FAILED ({s.detail})"
            typer.echo(
                f"{s.name:<10} {s.scene.robot.info['gripper']:<8} {how:<8} {verdict}; "
                f"{clearance_text(s.min_distance)}, {s.solve_time:.2f} s"
            )
        total = sum(s.solve_time for s in stages)
        verdict = "success" if ok else "FAILED"
        typer.echo(f"fetch seed {seed} ({collision}): {verdict}, {total:.1f} s in all")
    if animate is not None:
        from .viz import animate_paths

        title = f"fetch seed {seed}: {collision}"
        animate_paths([(s.scene, s.q) for s in stages], animate, title=title)
        if not json_output:
            typer.echo(f"wrote {animate}")
    if view3d:
        from .viz3d import view_plan

        view_plan([(s.scene, s.q) for s in stages])
    if not ok:
        raise typer.Exit(1)


@app.command("generate")
def generate_command(
    env: str = typer.Option(..., help="Environment: a-e or ur5e."),
    split: str = typer.Option("train", help="train (seed 0) or test (seed 1)."),
    n: int = typer.Option(None, min=1, help="Samples (default: the paper's 50 000 / 5 000)."),
    seed: int = typer.Option(None, min=0, help="Override the split's seed."),
    near: float = typer.Option(
        0.0,
        help="Fraction of samples drawn near contact: around the fetch task (ur5e), "
        "|f| < 3 cm (a-e).",
    ),
    workers: int = typer.Option(None, min=1, help="Worker processes (default: all cores)."),
    data: Path = typer.Option(None, help="Data root (default data/): <data>/<env>/<split>."),
) -> None:
    """Write a dataset of graphs and coal labels in resumable shards (finished shards are kept)."""
    from .data import DATA_DIR, SPLITS, generate, split_dir

    if split not in SPLITS:
        raise InputError(f"--split: expected one of {sorted(SPLITS)}, got {split!r}")
    split_seed, size = SPLITS[split]
    target = check_output_dir(split_dir(env, split, data or DATA_DIR), "--data")
    generate(
        env, size if n is None else n, split_seed if seed is None else seed, target, workers, near
    )
    typer.echo(f"wrote {target}")


GRAPHDISTNET_ONLY = ("--preset", "--name", "--set", "--run-dir", "--compile", "--init", "--extra")
CLEARANCENET_BUDGET = 120.0  # s: --time-budget of --model clearancenet when none is given


@app.command("train")
def train_command(
    env: str = typer.Option(..., help="Environment: a-e or ur5e (its data must exist)."),
    model: str = typer.Option("graphdistnet", help="graphdistnet or clearancenet."),
    preset: str = typer.Option(
        None, help="GraphDistNet: smooth (planner, the default) or faithful."
    ),
    name: str = typer.Option(
        None, help="GraphDistNet run name, runs/<env>-<name> (default: the preset)."
    ),
    set_: list[str] = typer.Option(
        [], "--set", help="GraphDistNet architecture or loss override key=json_value."
    ),
    n_train: int = typer.Option(
        None, min=2, help="Use only the first n training samples (≥ 2: 10 % validate)."
    ),
    batch: int = typer.Option(256, min=1, help="Batch size."),
    lr: float = typer.Option(1e-3, help="Adam learning rate (≥ 0; 0 keeps --init's weights)."),
    epochs: int = typer.Option(200, min=1, help="Epoch cap."),
    patience: int = typer.Option(10, min=1, help="Early stopping: epochs without improvement."),
    time_budget: float = typer.Option(
        None, help="Seconds of training (> 0; default none, clearancenet 120)."
    ),
    seed: int = typer.Option(0, min=0, help="Random seed."),
    device: str = typer.Option("cpu", help="cpu or cuda."),
    threads: int = typer.Option(1, help="torch threads."),
    data: Path = typer.Option(None, help="Data root (default: data/)."),
    out: Path = typer.Option(
        None, help="Weights path (default: weights/<env>.safetensors, clearancenet_<env>)."
    ),
    run_dir: Path = typer.Option(
        None, help="GraphDistNet checkpoints, loss curve (default runs/<env>-<name>)."
    ),
    compile: bool = typer.Option(
        False, "--compile", help="GraphDistNet: torch.compile the training step."
    ),
    init: str = typer.Option(
        None,
        help="Fine-tune from these GraphDistNet weights, a shipped name or a path (their "
        "card's config; --set applies).",
    ),
    extra: list[Path] = typer.Option(
        [],
        help="More GraphDistNet training shards (a directory, e.g. from generate --near); "
        "repeatable.",
    ),
) -> None:
    """Train a model on data/<env>/train, score it on data/<env>/test, write weights + card.

    Every option applies to GraphDistNet; the ones marked GraphDistNet (and --init, --extra)
    are refused with --model clearancenet instead of being ignored.
    """
    from .assets import weights_file
    from .data import DATA_DIR
    from .train import FitConfig

    _check_model(model, (preset, name, set_, run_dir, compile, init, extra))
    if model == "clearancenet" and time_budget is None:
        time_budget = CLEARANCENET_BUDGET
    schedule = FitConfig(batch, lr, epochs, patience, time_budget, seed, device)
    init = None if init is None else weights_file(init)
    if out is not None:
        check_output_path(out, (".safetensors",), "--out")
        check_output_path(out.with_suffix(".json"), (".json",), "--out")
    if run_dir is not None:
        check_output_dir(run_dir, "--run-dir")
    if model == "clearancenet":
        set_threads(threads, torch_global=True)
        card = _train_clearancenet(env, schedule, out, n_train, data or DATA_DIR)
        typer.echo(json.dumps({"env": env, **card["test"]}, indent=2))
        return
    config = _graphdistnet_run(preset, set_, init, schedule, n_train, extra, compile)
    set_threads(threads, torch_global=True)
    from . import train as training

    card = training.train(
        env, config, name or preset or "smooth", data_root=data or DATA_DIR, out=out,
        run_dir=run_dir,
    )  # fmt: skip
    typer.echo(json.dumps({"env": env, "name": card["name"], **card["test"]}, indent=2))


def _check_model(model: str, graphdistnet_only: tuple) -> None:
    """InputError naming the model, or the first GraphDistNet option given to ClearanceNet."""
    if model not in ("graphdistnet", "clearancenet"):
        raise InputError(f"--model: expected graphdistnet or clearancenet, got {model!r}")
    if model == "clearancenet":
        pairs = zip(GRAPHDISTNET_ONLY, graphdistnet_only, strict=True)
        given = [flag for flag, value in pairs if value]
        if given:
            raise InputError(
                f"{given[0]}: does not apply to --model clearancenet (GraphDistNet only); "
                f"drop {', '.join(given)}"
            )


def _train_clearancenet(env: str, schedule, out: Path | None, n_train: int | None, root: Path):
    """``gdnplan train --model clearancenet``: the card of the weights written."""
    from .train import train_and_score

    command = (
        f"gdnplan train --model clearancenet --env {env} --time-budget {schedule.time_budget:g} "
        f"--patience {schedule.patience} --epochs {schedule.epochs} --batch {schedule.batch} "
        f"--lr {schedule.lr:g} --seed {schedule.seed}"
        + (f" --n-train {n_train}" if n_train is not None else "")
    )
    return train_and_score(env, schedule, out, n_train, root, command)


def _graphdistnet_run(preset, set_, init, schedule, n_train, extra, compile):
    """The TrainConfig of ``gdnplan train`` (GraphDistNet) from its options."""
    from .train import PRESETS, TrainConfig, card_settings, split_config

    if preset is not None and preset not in PRESETS:
        raise InputError(f"--preset: expected one of {sorted(PRESETS)}, got {preset!r}")
    if preset is not None and init is not None:
        raise InputError(
            "--preset: does not apply with --init (the network is the --init weights' card's; "
            "change it with --set)"
        )
    try:
        overrides = {k: json.loads(v) for k, v in (s.split("=", 1) for s in set_)}
    except ValueError as e:
        raise InputError(f"--set: expected key=json_value, got {set_}") from e
    if init is None:
        base = PRESETS[preset or "smooth"]().to_dict()
    else:
        base = card_settings(init)
    try:
        network, loss = split_config(base | overrides)
    except (TypeError, ValueError) as e:
        if isinstance(e, InputError):
            raise InputError(f"--set: {e}") from e
        raise InputError(f"--set: a value of the wrong type in {set_} ({e})") from e
    return TrainConfig(network, loss, schedule, n_train, tuple(extra), init, compile)


FIELD_GRID_MAX = 1001  # 10⁶ configurations, minutes per model


@app.command("field")
def field_command(
    env: str = typer.Option("a", help="A 2-DoF environment (a or b)."),
    out: Path = typer.Option(Path("field.png"), help="Output PNG."),
    grid: int = typer.Option(101, min=2, max=FIELD_GRID_MAX, help="Grid points per joint."),
    quiet: bool = typer.Option(False, "--quiet", "-q", help=QUIET_HELP),
) -> None:
    """Distance fields over (q1, q2) from coal, DiffCo and GraphDistNet (paper Figure 5)."""
    from .evaluate import fig5
    from .viz import save_figure

    show_progress(not quiet)
    if env not in ("a", "b"):
        raise InputError(f"--env: expected a 2-DoF environment, a or b, got {env!r}")
    check_output_path(out, FIGURE_SUFFIXES, "--out")
    save_figure(fig5(env, grid, progress=not quiet), out)
    typer.echo(f"wrote {out}")


def run(args: list[str] | None = None) -> None:
    """Run the app on ``args`` (default: the command line); exits with the status of the module
    docstring, every error as one line on stderr."""
    _DEBUG["on"] = False
    try:
        code = app(args=args, prog_name="gdnplan", standalone_mode=False)
        if code == EXIT_INTERRUPTED:  # typer returns Ctrl-C in a command as exit code 130
            typer.echo("error: interrupted", err=True)
    except click_exceptions.NoArgsIsHelpError as e:
        e.show()
        code = EXIT_INPUT
    except click_exceptions.UsageError as e:
        hint = f"; see `{e.ctx.command_path} --help`" if e.ctx is not None else ""
        code = _fail(e, one_line(e.format_message()) + hint, EXIT_INPUT)
    except GdnplanError as e:
        code = _fail(e, one_line(str(e)), EXIT_INPUT)
    except (KeyboardInterrupt, typer.Abort) as e:
        code = _fail(e, "interrupted", EXIT_INTERRUPTED)
    except Exception as e:  # the last resort: a bug, never a traceback without --debug
        why = f"{type(e).__name__}: {one_line(str(e))}" if str(e) else type(e).__name__
        message = f"internal error ({why}); rerun with --debug for the traceback"
        code = _fail(e, message, EXIT_INTERNAL)
    finally:
        hide_progress()
    sys.exit(code if isinstance(code, int) else 0)


def _fail(e: BaseException, message: str, code: int) -> int:
    """Print ``error: message`` (after the traceback with ``--debug``); returns ``code``."""
    if _DEBUG["on"]:
        traceback.print_exception(e)
    typer.echo(f"error: {message}", err=True)
    return code


def one_line(text: str, limit: int = 400) -> str:
    """``text`` on one line (whitespace runs become one space), at most ``limit`` characters."""
    flat = " ".join(text.split())
    return flat if len(flat) <= limit else flat[: limit - 1] + "…"


def main() -> None:
    """Console entry point."""
    run()


if __name__ == "__main__":
    main()
