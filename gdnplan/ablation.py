"""From the paper's GraphDistNet to gdnplan's, one change a step (issue #25).

:data:`STEPS` starts at the paper's network (§IV, :meth:`GraphDistNetConfig.faithful`) and
each step changes one architecture field of the step before; every step is trained with the
same data, number of Adam steps (:data:`EPOCHS` epochs of the environment's training rows,
batch 256: a budget of optimiser steps, not seconds, because a CPU second on the shared machine
does less work when other jobs share its caches), seeds and loss (the paper's: the squared
distance error, no gradient or contact terms) and scored on the same held-out samples:

* MAE (m), AUC and ACD on the test split (the card's, :func:`gdnplan.train.report.evaluate`),
  the mean over training seeds ± its standard error s / √S (S ≥ 2 seeds);
* time of d̂ and ∂d̂/∂q per configuration (s), one batch of ``batch`` configurations in one
  scene, fastest of 5, one torch thread;
* sweep continuity: the largest |d̂(q + 0.003 e_j) − d̂(q)| (m) along 200-step sweeps of every
  joint from ``sweeps`` random configurations (scene seed 11);
* Table II: Ipopt's certified success, median wall and CPU time (s) on the reaching problems of the
  environment's setting (b, d; :func:`gdnplan.table2.reaching_problems`), when asked for.

:func:`faithful_config` is the faithful network's run for Table I: the data and the time
budget of the shipped (best) weights of the environment, :data:`BEST` (their cards).
Every trained step is kept (``results/ablation/<env>/<step>-s<seed>.safetensors`` + card, its
scores in ``….scores.json``; the repository keeps them, so the ≈ 14 h run accumulates over
sessions) and skipped when it has its epochs; an interrupted training, or one kept with fewer
epochs, resumes from its checkpoint (the schedule depends on the epoch count only, so a resumed
run equals one trained straight through); one kept with more epochs is trained again.

Modules: the steps, budgets and run sizes in :mod:`gdnplan.ablation_steps`, a step's columns in
:mod:`gdnplan.ablation_scores`, the markdown table in :mod:`gdnplan.ablation_table`; this
module trains, keeps and resumes, and re-exports their names.
"""

from __future__ import annotations

import json
import math
import shutil
import time
from collections.abc import Callable
from pathlib import Path

from .ablation_scores import grad_time, loaded_code, score, sweep_max, table2_ipopt, timing
from .ablation_steps import (
    BEST,
    ENVS,
    EPOCHS,
    PATIENCE,
    STEPS,
    TABLE2_SETTINGS,
    Best,
    Settings,
    extra_data,
    faithful_config,
    step_config,
)
from .ablation_table import markdown
from .data import DATA_DIR, split_dir
from .train import FitConfig, GraphDistNetLoss, TrainConfig

__all__ = [
    "BEST",
    "ENVS",
    "EPOCHS",
    "PATIENCE",
    "RUNS_DIR",
    "STEPS",
    "TABLE2_SETTINGS",
    "Best",
    "Settings",
    "faithful_config",
    "grad_time",
    "loaded_code",
    "markdown",
    "run",
    "score",
    "step_config",
    "sweep_max",
    "table2_ipopt",
    "timing",
    "train_step",
]


def _weights_path(runs: Path, env: str, step: int, seed: int) -> Path:
    return runs / env / f"{STEPS[step][0]}-s{seed}.safetensors"


def train_step(env: str, step: int, seed: int, s: Settings, data_root: Path, runs: Path) -> Path:
    """Train ``STEPS[step]`` with ``seed`` to ``s.epochs_of(env)`` epochs (skipped when kept
    with them; module docstring); the weights' path."""
    from .train import train

    out = _weights_path(runs, env, step, seed)
    name, epochs = out.stem, s.epochs_of(env)
    run_dir = runs / env / name
    if _trained(out, run_dir, epochs):
        return out
    if _checkpoint_epochs(run_dir) > epochs:
        shutil.rmtree(run_dir)  # trained past the budget: start over
    for kept in (out, out.with_suffix(".json"), out.with_suffix(".scores.json")):
        kept.unlink(missing_ok=True)  # they describe another number of epochs
    best = BEST[env]
    fit = FitConfig(batch=s.batch, epochs=epochs, patience=PATIENCE, seed=seed,
                    budget_clock="cpu")  # fmt: skip
    config = TrainConfig(step_config(step), GraphDistNetLoss(), fit, best.n_train,
                         extra_data(env, data_root))  # fmt: skip
    train(env, config, name, data_root=data_root, out=out, run_dir=run_dir)
    return out


def _trained(weights: Path, run_dir: Path, epochs: int) -> bool:
    """Whether the kept ``weights`` trained ``epochs`` epochs, or stopped early before them."""
    card = weights.with_suffix(".json")
    if not (weights.exists() and card.exists()):
        return False
    done = json.loads(card.read_text())["training"]["epochs"]
    if done == epochs:
        return True
    state = run_dir / "checkpoint.json"
    stopped = state.exists() and json.loads(state.read_text())["stale"] >= PATIENCE
    return done < epochs and stopped


def _checkpoint_epochs(run_dir: Path) -> int:
    """Epochs of the checkpoint in ``run_dir`` (0: none)."""
    state = run_dir / "checkpoint.json"
    return json.loads(state.read_text())["epoch"] if state.exists() else 0


RUNS_DIR = Path("results/ablation")  # trained steps, kept in the repository between sessions


def run(
    envs: tuple[str, ...] = ENVS,
    seeds: int = 2,
    s: Settings | None = None,
    data_root: Path | str = DATA_DIR,
    runs: Path | str = RUNS_DIR,
    log: Callable[[str], None] = print,
    train_for: float = math.inf,
    retime: bool = False,
) -> dict[str, list[list[dict]]]:
    """{env: [[scores of each trained seed] for each step]}, training and scoring what is
    missing. No step starts training once ``train_for`` seconds (wall) have passed (0: report
    the kept steps only); steps left untrained have fewer seeds' scores, or none. ``retime``:
    the d̂+∇ column of every kept step is measured again with this code (:func:`timing`)."""
    s = s or Settings()
    loaded_code()  # the code of this run, before any commit made while it trains
    data_root, runs = Path(data_root), Path(runs)
    deadline = time.monotonic() + train_for
    for env in envs:
        if train_for > 0 and not split_dir(env, "train", data_root).is_dir():
            raise FileNotFoundError(f"{split_dir(env, 'train', data_root)}: generate it first")
    # Seed-major: one seed of every environment and step before the next seed, so a partial
    # run already has a whole (single-seed) table.
    for seed in range(seeds):
        for env in envs:
            for step in range(len(STEPS)):
                weights = _weights_path(runs, env, step, seed)
                due = not _trained(weights, weights.with_suffix(""), s.epochs_of(env))
                if due and time.monotonic() < deadline:
                    train_step(env, step, seed, s, data_root, runs)
                if not weights.exists():
                    continue
                cached = weights.with_suffix(".scores.json")
                if not cached.exists():
                    cached.write_text(json.dumps(score(weights, env, s), indent=1) + "\n")
                elif retime:
                    from .models import load_model

                    model = load_model(weights, threads=1)
                    scores = json.loads(cached.read_text()) | timing(model, env, s)
                    cached.write_text(json.dumps(scores, indent=1) + "\n")
                log(f"ablation {env} {STEPS[step][0]} seed {seed}: {cached.read_text()}")
    return {env: [_kept_scores(runs, env, step, seeds) for step in range(len(STEPS))]
            for env in envs}  # fmt: skip


def _kept_scores(runs: Path, env: str, step: int, seeds: int) -> list[dict]:
    """The scores of ``STEPS[step]`` of every seed trained so far."""
    paths = (_weights_path(runs, env, step, seed).with_suffix(".scores.json")
             for seed in range(seeds))  # fmt: skip
    return [json.loads(p.read_text()) for p in paths if p.exists()]
