"""``gdnplan fetch``: the scripted UR5e fetch sequence."""

from __future__ import annotations

import json
from pathlib import Path
from typing import TYPE_CHECKING

import typer

from ..files import check_output_path

if TYPE_CHECKING:  # the commands import numpy and the library when they run: a fast --help
    pass

from .app import app
from .common import QUIET_HELP, THREADS_HELP, WEIGHTS_HELP, set_threads, show_progress
from .plan import echo_stages


@app.command("fetch")
def fetch_command(
    seed: int = typer.Option(0, min=0, help="Fetch layout: 0 canonical, others random storages."),
    collision: str = typer.Option(
        None,
        help="Collision model: graphdistnet or coal; default graphdistnet (planar), coal (--3d; "
        "graphdistnet there needs --weights trained on ur5e_storage).",
    ),
    weights: str = typer.Option(None, help=WEIGHTS_HELP),
    animate: Path = typer.Option(None, help="Write an animated GIF of all stages."),
    json_output: bool = typer.Option(False, "--json", help="Print one JSON object."),
    threads: int = typer.Option(1, help=THREADS_HELP),
    view3d: bool = typer.Option(False, "--view3d", help="3-D browser view (needs meshcat)."),
    quiet: bool = typer.Option(False, "--quiet", "-q", help=QUIET_HELP),
    three_d: bool = typer.Option(
        False, "--3d", help="The 3-D fetch: the full six-joint UR5e, coal-certified stages."
    ),
    placement: str = typer.Option(
        None, help="--3d: the storage's front-face centre and yaw 'x,y,yaw' (m, m, rad)."
    ),
    write_problems: str = typer.Option(
        None, help="--3d: write each planned stage's problem files into this directory."
    ),
) -> None:
    """The UR5e fetch: approach, reach in, grasp, lift, bring the stick out, retreat.

    Exit status: 0 when every stage is certified collision-free, 1 otherwise, 2 on bad input.
    """
    from ..errors import InputError
    from ..fetch import run_fetch

    show_progress(not quiet)
    if write_problems == "":
        raise InputError("--write-problems: expected a directory, got an empty string")
    if three_d:
        _check_3d_options(animate, view3d, collision, weights)
        from .fetch3d import run_fetch3d_command

        set_threads(threads)
        out = None if write_problems is None else Path(write_problems)
        model = "coal" if collision is None else collision
        if not run_fetch3d_command(seed, placement, json_output, out, model, weights):
            raise typer.Exit(1)
        return
    for flag, value in (("--placement", placement), ("--write-problems", write_problems)):
        if value is not None:
            raise InputError(f"{flag}: only the 3-D fetch takes it (add --3d)")
    if animate is not None:
        check_output_path(animate, (".gif",), "--animate")
    set_threads(threads)
    if view3d:  # fail before planning, not after
        from ..viz3d import require_meshcat

        require_meshcat()
    collision = "graphdistnet" if collision is None else collision
    stages = run_fetch(seed, collision=collision, weights=weights)
    ok = all(s.success for s in stages)
    if json_output:
        summary = {"seed": seed, "collision": collision, "success": ok}
        summary["stages"] = [s.summary() for s in stages]
        typer.echo(json.dumps(summary))
    else:
        total = echo_stages(stages, [s.scene.robot.info["gripper"] for s in stages])
        verdict = "success" if ok else "FAILED"
        typer.echo(f"fetch seed {seed} ({collision}): {verdict}, {total:.1f} s in all")
    if animate is not None:
        from ..viz import animate_paths

        title = f"fetch seed {seed}: {collision}"
        animate_paths([(s.scene, s.q) for s in stages], animate, title=title)
        if not json_output:
            typer.echo(f"wrote {animate}")
    if view3d:
        from ..viz3d import view_plan

        view_plan([(s.scene, s.q) for s in stages])
    if not ok:
        raise typer.Exit(1)


def _check_3d_options(animate, view3d: bool, collision: str | None, weights: str | None) -> None:
    """InputError naming the first option the 3-D fetch does not take, and what to do."""
    from ..errors import InputError

    if animate is not None or view3d:
        flag = "--animate" if animate is not None else "--view3d"
        raise InputError(
            f"{flag}: the 3-D fetch draws no GIF or browser view yet; write its stages with "
            "--write-problems DIR and view one with gdnplan plan DIR/fetch3d_<stage>.toml "
            f"{flag}{' out.gif' if flag == '--animate' else ''}"
        )
    if collision not in (None, "coal", "graphdistnet"):
        raise InputError(
            f"--collision: expected coal or graphdistnet for the 3-D fetch, got {collision!r}"
        )
    if weights is not None and collision != "graphdistnet":
        raise InputError(
            "--weights: the 3-D fetch takes weights only with --collision graphdistnet "
            "(weights trained on ur5e_storage)"
        )
