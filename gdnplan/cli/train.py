"""``gdnplan generate`` and ``gdnplan train``: datasets and training from the command line."""

from __future__ import annotations

import json
from pathlib import Path
from typing import TYPE_CHECKING

import typer

from ..errors import InputError
from ..files import check_output_dir, check_output_path

if TYPE_CHECKING:  # the commands import numpy and the library when they run: a fast --help
    pass

from .app import app
from .common import check_not_shipped, set_threads


@app.command("generate")
def generate_command(
    env: str = typer.Option(
        ..., help="Environment: a-e, ur5e, or ur5e_boxes, ur5e_cloud, ur5e_storage (3-D)."
    ),
    split: str = typer.Option("train", help="train (seed 0) or test (seed 1)."),
    n: int = typer.Option(
        None,
        min=1,
        max=10**8,
        help="Samples, 1 … 10⁸ (default: the paper's 50 000 / 5 000); ~150 B (2-DoF) to ~1.1 kB "
        "(e) of disk each.",
    ),
    seed: int = typer.Option(None, min=0, help="Override the split's seed."),
    near: float = typer.Option(
        0.0,
        help="Fraction of samples drawn near contact: around the fetch task (ur5e), "
        "|f| < 3 cm (a-e).",
    ),
    workers: int = typer.Option(
        None, min=1, help="Worker processes, 1 … 4 per core (default: all cores)."
    ),
    data: Path = typer.Option(None, help="Data root (default data/): <data>/<env>/<split>."),
    ray: bool = typer.Option(
        False,
        "--ray",
        help="3-D environments: make the shards as Ray tasks (a local Ray instance).",
    ),
    ray_address: str = typer.Option(
        None, help="With --ray: the Ray cluster to join (e.g. auto, ray://head:10001)."
    ),
) -> None:
    """Write a dataset of graphs and coal labels in resumable shards (finished shards are kept)."""
    from ..data import DATA_DIR, SPLITS, generate, split_dir
    from ..data.samples3d import ENVS3D

    if split not in SPLITS:
        raise InputError(f"--split: expected one of {sorted(SPLITS)}, got {split!r}")
    split_seed, size = SPLITS[split]
    if ray_address is not None and not ray:
        raise InputError("--ray-address: needs --ray")
    if ray and env not in ENVS3D:
        raise InputError(f"--ray: only for the 3-D environments {list(ENVS3D)}, not {env!r}")
    target = check_output_dir(split_dir(env, split, data or DATA_DIR), "--data")
    if env in ENVS3D:
        from ..data.shards3d import generate3d

        seed = split_seed if seed is None else seed
        backend = (ray_address or "local") if ray else None
        generate3d(env, size if n is None else n, seed, target, workers, near, backend)
        typer.echo(f"wrote {target}")
        return
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
    replace_shipped: bool = typer.Option(
        False,
        "--replace-shipped",
        help="Allow the weights to replace a shipped weights file (how the shipped ones are "
        "reproduced; every plan by that name then uses the new weights).",
    ),
) -> None:
    """Train a model on data/<env>/train, score it on data/<env>/test, write weights + card.

    Every option applies to GraphDistNet; the ones marked GraphDistNet (and --init, --extra)
    are refused with --model clearancenet instead of being ignored.
    """
    from ..assets import weights_file
    from ..data import DATA_DIR
    from ..train import FitConfig

    _check_model(model, (preset, name, set_, run_dir, compile, init, extra))
    if model == "clearancenet" and time_budget is None:
        time_budget = CLEARANCENET_BUDGET
    schedule = FitConfig(batch, lr, epochs, patience, time_budget, seed, device)
    init = None if init is None else weights_file(init)
    default = f"clearancenet_{env}" if model == "clearancenet" else env
    target = out if out is not None else Path("weights") / f"{default}.safetensors"
    if out is not None:
        check_output_path(out, (".safetensors",), "--out")
        check_output_path(out.with_suffix(".json"), (".json",), "--out")
    if run_dir is not None:
        check_output_dir(run_dir, "--run-dir")
    if model == "clearancenet":
        check_not_shipped(target, replace_shipped)
        set_threads(threads, torch_global=True)
        card = _train_clearancenet(env, schedule, out, n_train, data or DATA_DIR)
        typer.echo(json.dumps({"env": env, **card["test"]}, indent=2))
        return
    config = _graphdistnet_run(preset, set_, init, schedule, n_train, extra, compile)
    check_not_shipped(target, replace_shipped)
    set_threads(threads, torch_global=True)
    from .. import train as training

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
    from ..train import train_and_score

    command = (
        f"gdnplan train --model clearancenet --env {env} --time-budget {schedule.time_budget:g} "
        f"--patience {schedule.patience} --epochs {schedule.epochs} --batch {schedule.batch} "
        f"--lr {schedule.lr:g} --seed {schedule.seed}"
        + (f" --n-train {n_train}" if n_train is not None else "")
    )
    return train_and_score(env, schedule, out, n_train, root, command)


def _graphdistnet_run(preset, set_, init, schedule, n_train, extra, compile):
    """The TrainConfig of ``gdnplan train`` (GraphDistNet) from its options."""
    from ..train import PRESETS, TrainConfig, card_settings, split_config

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
        check_init(init)
        base = card_settings(init)
    try:
        network, loss = split_config(base | overrides)
    except (TypeError, ValueError) as e:
        if isinstance(e, InputError):
            raise InputError(f"--set: {e}") from e
        raise InputError(f"--set: a value of the wrong type in {set_} ({e})") from e
    return TrainConfig(network, loss, schedule, n_train, tuple(extra), init, compile)


def check_init(path) -> None:
    """InputError unless the weights ``path`` of ``--init`` are planar GraphDistNet weights
    whose tensors load (:func:`gdnplan.train.graphdistnet.init_tensors`), before the data."""
    from ..train.graphdistnet import init_tensors

    init_tensors(Path(path))
