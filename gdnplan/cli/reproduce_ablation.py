"""``gdnplan reproduce ablation`` (the paper's GraphDistNet to gdnplan's, one change a step) and
``gdnplan reproduce faithful`` (the paper's GraphDistNet for Table I), in the ``reproduce`` group
of :mod:`~gdnplan.cli.reproduce`."""

from __future__ import annotations

from pathlib import Path

import typer

from ..errors import InputError
from ..files import FIGURE_SUFFIXES, check_output_path, write_text
from .common import THREADS_HELP, check_not_shipped, set_threads
from .reproduce import no_repeats, reproduce_app


@reproduce_app.command("ablation")
def ablation_command(
    fast: bool = typer.Option(False, "--fast", help="Tiny data, one epoch (CI; not a result)."),
    envs: str = typer.Option("b,d,e", help="Environments (comma-separated)."),
    seeds: int = typer.Option(2, min=1, help="Training seeds per step."),
    epochs: int = typer.Option(
        None, min=1, help="Epochs per step and seed (default: gdnplan.ablation.EPOCHS)."
    ),
    data: Path = typer.Option(None, help="Data root (default data/; --fast: a temporary one)."),
    runs: Path = typer.Option(
        Path("results/ablation"), help="Trained steps (kept in the repository, skipped)."
    ),
    train_for: float = typer.Option(
        None, help="Start no training after this many seconds (0: table of the kept steps)."
    ),
    out: Path = typer.Option(Path("results/ablation.md"), help="Markdown output."),
    figure: Path = typer.Option(
        None, help="Also plot the columns over the steps (.png, .pdf, .svg)."
    ),
    retime: bool = typer.Option(
        False, "--retime", help="Measure every kept step's d̂+∇ again with this code."
    ),
) -> None:
    """Faithful → soft partners → one-way → node distances → soft-minimum readout → probe
    points → band readout, one change a step, same data, epochs and seeds (resumable)."""
    import datetime
    import tempfile

    from .. import ablation
    from ..data import DATA_DIR, generate, split_dir

    check_output_path(out, (".md",), "--out")
    if figure is not None:
        check_output_path(figure, FIGURE_SUFFIXES, "--figure")
    chosen = no_repeats(tuple(e.strip() for e in envs.split(",") if e.strip()), "--envs")
    if not chosen or any(e not in ablation.BEST for e in chosen):
        raise InputError(f"--envs: expected some of {sorted(ablation.BEST)}, got {envs!r}")
    if train_for is not None and not 0 <= train_for < float("inf"):
        raise InputError(f"--train-for: expected seconds ≥ 0, got {train_for}")
    set_threads(1, torch_global=True)
    s = ablation.Settings.fast() if fast else ablation.Settings(epochs=epochs)
    with tempfile.TemporaryDirectory() as tmp:
        root = data or (Path(tmp) / "data" if fast else DATA_DIR)
        if fast:
            runs = Path(tmp) / "runs"
            for env in chosen:
                for split, seed, n in (("train", 0, 40), ("test", 1, 24)):
                    target = split_dir(env, split, root)
                    if not target.exists():
                        generate(env, n, seed, target, workers=1)
        limit = float("inf") if train_for is None else train_for
        results = ablation.run(
            chosen, seeds, s, root, runs, log=lambda m: typer.echo(m, err=True),
            train_for=limit, retime=retime,
        )  # fmt: skip
    command = (
        f"gdnplan reproduce ablation{' --fast' if fast else ''} --envs {','.join(chosen)} "
        f"--seeds {seeds}" + (f" --epochs {epochs}" if epochs and not fast else "")
    )
    text = "\n".join([
        "# Ablation: the paper's GraphDistNet to gdnplan's, one change a step"
        + (" (fast mode: tiny data, not a result)" if fast else ""),
        "",
        f"- command: `{command}`",
        f"- date: {datetime.datetime.now().isoformat(timespec='seconds')}",
        "",
        ablation.markdown(results, s),
    ])  # fmt: skip
    typer.echo(text)
    write_text(out, text, "--out")
    if figure is not None:
        from ..viz import ablation_figure, save_figure

        save_figure(ablation_figure([name for name, _, _ in ablation.STEPS], results), figure)
        typer.echo(f"wrote {figure}", err=True)


@reproduce_app.command("faithful")
def faithful_command(
    env: str = typer.Option(..., help="Environment a-e (its data must exist, as for train)."),
    data: Path = typer.Option(None, help="Data root (default data/)."),
    budget: float = typer.Option(None, help="Training seconds (default: the shipped weights')."),
    out: Path = typer.Option(
        None,
        help="Weights (default: the shipped <env>_faithful.safetensors; needs --replace-shipped).",
    ),
    threads: int = typer.Option(1, help=THREADS_HELP),
    replace_shipped: bool = typer.Option(
        False, "--replace-shipped", help="Allow the weights to replace the shipped file."
    ),
) -> None:
    """Train the paper's GraphDistNet (§IV) for Table I on the data and time budget of the
    environment's shipped weights; rerun the same command to resume (runs/faithful/<env>)."""
    from .. import ablation
    from ..assets import WEIGHTS_DIR
    from ..train import train

    if env not in ablation.BEST:
        raise InputError(f"--env: expected one of {sorted(ablation.BEST)}, got {env!r}")
    if budget is not None and not budget > 0:
        raise InputError(f"--budget: expected a positive number of seconds, got {budget}")
    out = out or WEIGHTS_DIR / f"{env}_faithful.safetensors"
    check_not_shipped(out, replace_shipped)
    check_output_path(out, (".safetensors",), "--out")
    set_threads(threads, torch_global=True)
    config = ablation.faithful_config(env, data or Path("data"), budget)
    card = train(env, config, "faithful", data_root=data or Path("data"), out=out,
                 run_dir=Path("runs/faithful") / env)  # fmt: skip
    typer.echo(f"wrote {out}: test {card['test']}")
