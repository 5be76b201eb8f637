"""``gdnplan show`` and ``gdnplan plan`` (their text and JSON reports: :mod:`.plan_report`)."""

from __future__ import annotations

import ctypes
import json
import os
import sys
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING

import typer

from ..errors import InputError
from ..files import FIGURE_SUFFIXES, check_output_path

if TYPE_CHECKING:  # the commands import numpy and the library when they run: a fast --help
    pass

from .app import app
from .common import (
    PROBLEM_HELP,
    QUIET_HELP,
    THREADS_HELP,
    WEIGHTS_HELP,
    check_limits,
    parse_vector,
    scene_and_start,
    set_threads,
    show_progress,
)
from .plan_report import clearance_text as clearance_text
from .plan_report import echo_stages as echo_stages
from .plan_report import json_number as json_number
from .plan_report import plan_summary as plan_summary
from .plan_report import stage_clearance as stage_clearance
from .plan_report import timing_text as timing_text


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
    from ..viz import save_figure, scene_figure

    check_output_path(out, FIGURE_SUFFIXES, "--out")
    scene, start = scene_and_start(target, seed)
    if is_3d(scene):
        raise InputError(f"show: {target} is a 3-D problem; show draws planar scenes only")
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
    collision: str = typer.Option(
        None,
        help="Collision model: graphdistnet or coal; default: graphdistnet for a planar "
        "problem, coal for a 3-D one (graphdistnet in 3-D needs --weights, e.g. "
        "ur5e_boxes3d_preliminary).",
    ),
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
        "file's [seed] count, else 3 (with --time-budget: as many as fit).",
    ),
    time_budget: float = typer.Option(
        None,
        help="Wall-time budget (s): return the cheapest certified path found when it ends.",
    ),
    json_output: bool = typer.Option(False, "--json", help="Print one JSON object."),
    animate: Path = typer.Option(
        None,
        help="Write an animated GIF of the plan (3-D problems: the arm, the obstacles and "
        "the clearance along the timed path).",
    ),
    threads: int = typer.Option(1, help=THREADS_HELP),
    view3d: bool = typer.Option(
        False, "--view3d", help="3-D browser view (needs meshcat); planar and 3-D problems."
    ),
    max_acceleration: float = typer.Option(
        None,
        help="Joint acceleration limit (rad/s²) of the timing: a smooth curve with its own "
        "certificate (planar and 3-D); default: velocity limits only.",
    ),
    quiet: bool = typer.Option(False, "--quiet", "-q", help=QUIET_HELP),
) -> None:
    """Plan a collision-free trajectory; success is certified by a dense coal check.

    Exit status: 0 when the plan is certified, 1 when planning failed, 2 on bad input.
    """
    from ..trajopt import Problem, plan

    show_progress(not quiet)
    if animate is not None:
        check_output_path(animate, (".gif",), "--animate")
    set_threads(threads)
    if view3d:  # fail before planning, not after
        from ..viz3d import require_meshcat

        require_meshcat()
    problem = Problem.from_toml(problem_file)
    if collision is None:
        collision = "coal" if is_3d(problem.scene) else "graphdistnet"
    config = plan_flags_config(problem, solver, seeds, time_budget)
    with stdout_to_stderr(json_output):  # --json: Ipopt's print_level log must not reach stdout
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
        timed = "" if result.trajectory is None else f", {timing_text(result.trajectory)}"
        typer.echo(
            f"{problem_file}: {verdict}; {clearance_text(result.min_distance)}, "
            f"solve time {result.solve_time:.2f} s, {result.iterations} iterations, "
            f"path cost {result.path_cost:.3f}{timed}"
        )
    title = f"{Path(problem_file).name}: {collision}"
    # a 3-D plan is shown along its timed path (the polygon, or the certified smooth curve)
    shown = result.q if result.trajectory is None else result.trajectory
    if animate is not None:
        if is_3d(problem.scene):
            from ..viz3d.animate import animate_paths3d

            animate_paths3d([(problem.scene, shown)], animate, title=title, margin=result.clearance)
        else:
            from ..viz import animate_paths

            animate_paths([(problem.scene, result.q)], animate, title=title)
        if not json_output:
            typer.echo(f"wrote {animate}")
    if view3d:
        from ..viz3d import view_plan

        view_plan([(problem.scene, shown if is_3d(problem.scene) else result.q)])
    if not result.success:
        raise typer.Exit(1)


@contextmanager
def stdout_to_stderr(active: bool = True) -> Iterator[None]:
    """While active, file descriptor 1 (stdout) points at stderr: what native code prints
    (Ipopt's log at ``print_level`` > 0, CasADi's warnings) goes to stderr, so ``--json``
    stdout holds the JSON object alone. Python's and C's stdout buffers are flushed on both
    sides of the switch."""
    if not active:
        yield
        return
    sys.stdout.flush()
    saved = os.dup(1)
    try:
        os.dup2(2, 1)
        yield
    finally:
        sys.stdout.flush()
        _flush_c_stdio()
        os.dup2(saved, 1)
        os.close(saved)


def _flush_c_stdio() -> None:
    """fflush(NULL): C stdio's buffered output (Ipopt prints through it) written out now."""
    try:
        ctypes.CDLL(None).fflush(None)
    except (OSError, AttributeError):  # no C library to ask (not expected on Linux/macOS)
        pass


def is_3d(scene) -> bool:
    """True for a 3-D scene (:class:`gdnplan.arm3d.Scene3D`)."""
    from ..arm3d.scene3d import Scene3D

    return isinstance(scene, Scene3D)


def plan_flags_config(problem, solver: str | None, seeds: int | None, time_budget: float | None):
    """The PlanConfig of ``gdnplan plan``: the problem file's settings, with the optimiser
    ``--solver`` names (the file's settings for it when the file is set up for it, else its
    defaults) and ``--seeds`` / ``--time-budget`` over the file's ``[seed]`` table."""
    from dataclasses import replace

    from ..trajopt import AdamConfig, PlanConfig
    from ..trajopt.config import OPTIMIZERS, with_optimizer

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
