"""``gdnplan evaluate``, ``gdnplan reproduce table1|table2`` and ``gdnplan field``: the paper's
tables and Figure 5 (``reproduce ablation|faithful``: :mod:`~gdnplan.cli.reproduce_ablation`)."""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING

import typer

from ..errors import InputError
from ..files import FIGURE_SUFFIXES, check_output_dir, check_output_path, write_text

if TYPE_CHECKING:  # the commands import numpy and the library when they run: a fast --help
    pass

from .app import app
from .common import QUIET_HELP, THREADS_HELP, set_threads, show_progress

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
    from .. import evaluate as ev
    from ..scene import make_scene

    if model not in EVAL_MODELS:
        raise InputError(f"--model: unknown {model!r}; choose one of {list(EVAL_MODELS)}")
    if env not in ev.ENVS:
        raise InputError(f"--env: expected one of {list(ev.ENVS)}, got {env!r}")
    if model == "coal":
        from ..models import CoalModel

        chosen = CoalModel()
    elif model == "diffco":
        from ..models.diffco import DiffCo

        chosen = DiffCo.train(make_scene(ev.DIFFCO_SOURCE.get(env, env)), n=3000)
        if env not in ev.DIFFCO_OWN_SCENE:  # Table I's "DiffCo (w/o AL)": the trained layout
            chosen = chosen.ignoring_obstacles()
    else:
        loader = ev.clearancenet_of_env if model == "clearancenet" else ev.graphdistnet_of_env
        chosen = loader(env)
        if chosen is None:
            raise InputError(f"--model: no {model} weights for env {env} in weights/")
    if n_grad > n:
        raise InputError(
            f"--n-grad: {n_grad} is more than --n {n} (the ACD uses the first of them)"
        )
    r = ev.evaluate_model(chosen, env, n, n_grad)
    mae = "N/A" if r.mae is None else f"{r.mae:.4f} m ({r.mae_reach:.4f} of reach)"
    acd = "N/A" if r.acd is None else f"{r.acd:.4f} ± {_se(r.acd_se)} over {r.n_grad}"
    auc = f"{r.auc:.4f}" if math.isfinite(r.auc) else f"N/A (one class among {r.n} samples)"
    typer.echo(
        f"{model} env {env}: n={r.n} time {r.seconds:.4f} s, MAE {mae}, AUC {auc}, ACD {acd}"
    )


def _se(value: float) -> str:
    """A standard error as printed: N/A where one sample leaves it undefined (NaN)."""
    return f"{value:.4f}" if math.isfinite(value) else "N/A (one sample)"


def no_repeats(items, flag: str) -> tuple:
    """``items`` as a tuple, InputError naming ``flag`` when one is given twice (a run would
    do it twice and print it twice)."""
    seen = [x for i, x in enumerate(items) if x in items[:i]]
    if seen:
        raise InputError(f"{flag}: {seen[0]!r} is given twice")
    return tuple(items)


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

    from .. import evaluate as ev

    check_output_path(out, (".md",), "--out")
    if figures is not None:
        check_output_dir(figures, "--figures")
    if weights is not None and not weights.is_dir():
        raise InputError(f"--weights: {weights} is not a directory of weights")
    weights = weights or ev.WEIGHTS_DIR
    if not envs or any(e not in ev.ENVS for e in envs):
        raise InputError(f"--envs: expected letters from 'abcde', got {envs!r}")
    results, missing, used = ev.table1(
        no_repeats(tuple(envs), "--envs"),
        fast,
        log=lambda m: typer.echo(m, err=True),
        weights_dir=weights,
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
    text = "\n".join(header) + ev.table1_markdown(results, weights) + "\n"
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
    from .. import table2

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


FIELD_GRID_MAX = 1001  # 10⁶ configurations, minutes per model


@app.command("field")
def field_command(
    env: str = typer.Option("a", help="A 2-DoF environment (a or b)."),
    out: Path = typer.Option(Path("field.png"), help="Output PNG."),
    grid: int = typer.Option(101, min=2, max=FIELD_GRID_MAX, help="Grid points per joint."),
    quiet: bool = typer.Option(False, "--quiet", "-q", help=QUIET_HELP),
) -> None:
    """Distance fields over (q1, q2) from coal, DiffCo and GraphDistNet (paper Figure 5)."""
    from ..evaluate import fig5
    from ..viz import save_figure

    show_progress(not quiet)
    if env not in ("a", "b"):
        raise InputError(f"--env: expected a 2-DoF environment, a or b, got {env!r}")
    check_output_path(out, FIGURE_SUFFIXES, "--out")
    save_figure(fig5(env, grid, progress=not quiet), out)
    typer.echo(f"wrote {out}")
