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
  scene, fastest of 3, one torch thread;
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
"""

from __future__ import annotations

import functools
import json
import math
import shutil
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .data import DATA_DIR, split_dir
from .models.graphdistnet import GraphDistNetConfig
from .train import FitConfig, GraphDistNetLoss, TrainConfig, git_sha

__all__ = [
    "BEST",
    "ENVS",
    "EPOCHS",
    "RUNS_DIR",
    "STEPS",
    "Best",
    "Settings",
    "faithful_config",
    "grad_time",
    "markdown",
    "run",
    "score",
    "step_config",
    "sweep_max",
    "table2_ipopt",
    "train_step",
]

# (name, what changes, the one field changed), cumulative from the paper's network.
STEPS: tuple[tuple[str, str, dict], ...] = (
    ("faithful", "the paper (§IV): random, then argmax partner per graph, two-way", {}),
    ("soft-partners", "soft nearest-node partners instead of argmax", {"cross": "soft_knn"}),
    ("one-way", "cross edges into the robot graph only", {"two_way": False}),
    ("node-distances", "every node's signed distance to the other graph", {"node_distance": True}),
    ("soft-min", "d̂ = soft minimum of node distances + MLP", {"min_readout": True}),
    ("probe-points", "the soft minimum also over 4 points per edge", {"probe_split": 5}),
    ("band", "d̂ = the soft minimum beyond ≈ 2 cm of contact", {"correction_band": 0.01}),
)
ENVS = ("b", "d", "e")
# Epochs per step and seed: about what the 4 × 32 steps trained in 1 200 CPU s on a quiet
# machine (docs/decisions.md, 2026-12-04, fifth session).
EPOCHS = {"a": 50, "b": 50, "c": 50, "d": 10, "e": 10}
PATIENCE = 40  # epochs without a better validation MAE before a step stops early
TABLE2_SETTINGS = ("b", "d")  # environments with a Table II setting of their own


@dataclass(frozen=True)
class Best:
    """Data and training seconds of an environment's shipped weights (weights/<env>.json and
    its lineage: the sum of every training step from scratch)."""

    seconds: float
    n_train: int | None  # first samples of data/<env>/train (None: all 50 000)
    near: bool  # + the 20 000 near-boundary samples of data/near/<env>/train (seed 3)
    compile: bool  # their runs used torch.compile (the cards: d and e)


BEST = {
    "a": Best(2242 + 1560 + 1250, None, True, False),
    "b": Best(447 + 3075, None, False, False),
    "c": Best(1569 + 1608 + 792, None, True, False),
    "d": Best(1218, None, False, False),  # the small soft-minimum network (d_faithful: 4 287 s,
    # the budget of the one-way network shipped before it)
    "e": Best(1207, 45_000, False, False),  # the same small network (e_faithful: 4 573 s)
}


def step_config(step: int) -> GraphDistNetConfig:
    """The network of ``STEPS[step]``: the faithful one with every change up to it."""
    changes: dict = {}
    for _, _, change in STEPS[: step + 1]:
        changes |= change
    return GraphDistNetConfig.faithful().with_(**changes)


def _extra(env: str, data_root: Path | str) -> tuple[str, ...]:
    return (str(Path(data_root) / "near" / env / "train"),) if BEST[env].near else ()


def faithful_config(
    env: str, data_root: Path | str = DATA_DIR, budget: float | None = None
) -> TrainConfig:
    """The paper's network and loss on the data and time budget of ``env``'s shipped weights
    (:data:`BEST`; ``budget`` overrides the seconds), patience 40, no epoch cap below 1000."""
    best = BEST[env]
    fit = FitConfig(epochs=1000, patience=40, time_budget=budget or best.seconds)
    return TrainConfig(
        GraphDistNetConfig.faithful(),
        GraphDistNetLoss(),
        fit,
        best.n_train,
        _extra(env, data_root),
        compile=best.compile,
    )


@dataclass(frozen=True)
class Settings:
    """Sizes of one ablation run (:meth:`fast` for CI)."""

    epochs: int | None = None  # epochs per step and seed (None: EPOCHS of the environment)
    batch: int = 256
    sweeps: int = 3  # random start configurations of the joint sweeps
    sweep_steps: int = 200
    timing_batch: int = 256
    table2: int = 20  # reaching problems (0: no Table II column)

    @classmethod
    def fast(cls) -> Settings:
        return cls(epochs=1, batch=16, sweeps=1, sweep_steps=20, timing_batch=16,
                   table2=0)  # fmt: skip

    def epochs_of(self, env: str) -> int:
        """The epochs each step of ``env`` trains for."""
        return self.epochs or EPOCHS[env]


def sweep_max(model, scene, sweeps: int = 3, steps: int = 200) -> float:
    """Largest |Δd̂| (m) between consecutive 0.003 rad steps of sweeps of every joint."""
    robot = scene.robot
    worst = 0.0
    for q0 in robot.sample(sweeps, seed=7):
        for j in range(robot.dof):
            q = np.repeat(q0[None], steps, 0)
            q[:, j] = np.clip(
                q0[j] - 0.3 + 0.003 * np.arange(steps), robot.lower[j], robot.upper[j]
            )
            worst = max(worst, float(np.abs(np.diff(model.distance(scene, q))).max()))
    return worst


def grad_time(model, scene, batch: int) -> float:
    """CPU seconds of this process per configuration of d̂ and ∂d̂/∂q over one batch (fastest
    of 5; the model on one thread, so the work, however busy the shared machine)."""
    q = scene.robot.sample(batch, seed=3)
    model.distance_and_grad(scene, q[:2])  # scene cache, warm-up
    best = np.inf
    for _ in range(5):
        start = time.process_time()
        model.distance_and_grad(scene, q)
        best = min(best, time.process_time() - start)
    return best / batch


def table2_ipopt(model, setting: str, n: int) -> tuple[int, float, float]:
    """(certified successes, median wall time s, median CPU time s) of Ipopt with ``model`` on
    Table II's ``setting`` problems 0 … n − 1; the CPU time is the process's (the work, however
    busy the shared machine)."""
    from .table2 import reaching_problems
    from .trajopt import PlanConfig, plan
    from .trajopt.config import with_optimizer

    config = with_optimizer(PlanConfig(), "ipopt")
    ok, wall, cpu = 0, [], []
    for i, p in enumerate(reaching_problems(setting, n)):
        start = time.process_time()
        r = plan(p, collision=model, solver=config, seed=i)
        cpu.append(time.process_time() - start)
        ok, wall = ok + bool(r.success), [*wall, r.solve_time]
    return ok, float(np.median(wall)), float(np.median(cpu))


def score(weights: Path, env: str, s: Settings) -> dict:
    """The ablation's columns of one trained step (module docstring)."""
    from .models import load_model
    from .scene import make_scene

    model = load_model(weights, threads=1)
    card = json.loads(weights.with_suffix(".json").read_text())
    test, scene = card["test"], make_scene(env, seed=11)
    out = {
        "mae": test["mae_m"], "auc": test["auc"], "acd": test["acd"], "n_test": test["n"],
        "seconds": card["training"]["seconds"], "epochs": card["training"]["epochs"],
        "sweep_max": sweep_max(model, scene, s.sweeps, s.sweep_steps),
    } | timing(model, env, s)  # fmt: skip
    if s.table2 and env in TABLE2_SETTINGS:
        out["t2_success"], out["t2_median"], out["t2_cpu"] = table2_ipopt(model, env, s.table2)
        out["t2_n"], out["t2_git"] = s.table2, loaded_code()  # the planner that solved them
    return out


@functools.cache
def loaded_code() -> str:
    """The commit checked out when this process first asked (its run's start): the code it
    loaded, not a commit made while it ran (:func:`~.train.git_sha` at the time of asking)."""
    return git_sha()


def timing(model, env: str, s: Settings) -> dict:
    """The d̂+∇ column of one trained step's loaded ``model`` (:func:`grad_time`) and the code
    that measured it (``time_git``: the inference kernels change under kept steps;
    ``--retime`` measures again)."""
    from .scene import make_scene

    return {"grad_time": grad_time(model, make_scene(env, seed=11), s.timing_batch),
            "time_git": loaded_code()}  # fmt: skip


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
                         _extra(env, data_root))  # fmt: skip
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


def _mean_se(values: list[float], fmt: str) -> str:
    v = np.asarray(values, float)
    if len(v) < 2:
        return format(v.mean(), fmt)
    return f"{format(v.mean(), fmt)} ± {format(v.std(ddof=1) / np.sqrt(len(v)), fmt)}"


def markdown(results: dict[str, list[list[dict]]], s: Settings) -> str:
    """The ablation table (one row per environment and step) and its notes."""
    head = ("| env | step | change | MAE (mm) | AUC | ACD | d̂+∇ (ms/config) | sweep max (cm) "
            "| Table II Ipopt | median (s) | median CPU (s) | train s (epochs) |")  # fmt: skip
    lines = [head, "|" + "---|" * 12]
    for env, steps in results.items():
        for (name, change, _), runs in zip(STEPS, steps, strict=True):
            if not runs:
                lines.append(f"| {env} | {name} | {change} |" + " not trained yet |" * 9)
                continue
            t2 = "–", "–", "–"
            if all("t2_success" in r for r in runs):
                ok, n = sum(r["t2_success"] for r in runs), sum(r["t2_n"] for r in runs)
                cpu = [r["t2_cpu"] for r in runs if "t2_cpu" in r]
                t2 = (f"{ok}/{n}", f"{np.median([r['t2_median'] for r in runs]):.2f}",
                      f"{np.median(cpu):.2f}" if len(cpu) == len(runs) else "–")  # fmt: skip
            lines.append(
                f"| {env} | {name} | {change} | {_mean_se([1e3 * r['mae'] for r in runs], '.2f')} "
                f"| {_mean_se([r['auc'] for r in runs], '.4f')} "
                f"| {_mean_se([r['acd'] for r in runs], '.3f')} "
                f"| {1e3 * np.mean([r['grad_time'] for r in runs]):.3f} "
                f"| {100 * max(r['sweep_max'] for r in runs):.2f} | {t2[0]} | {t2[1]} | {t2[2]} "
                f"| {np.mean([r['seconds'] for r in runs]):.0f} "
                f"({'/'.join(str(r['epochs']) for r in runs)}) |"
            )
    n_test = sorted({r["n_test"] for steps in results.values() for runs in steps for r in runs})
    return (
        "\n".join(lines) + "\n" + notes(s, "/".join(map(str, n_test)), tuple(results))
        + _short(results, s)
        + _versions(results, "t2_git", "Table II rows were solved by", "planner",
                    "delete the `.scores.json` files to re-score")
        + _versions(results, "time_git", "d̂+∇ was measured by", "code",
                    "`--retime` measures every kept step again")
    )  # fmt: skip


def _short(results: dict[str, list[list[dict]]], s: Settings) -> str:
    """A note naming the rows with a seed trained for other than the environment's epochs
    (kept from an earlier budget, until a run trains them to it)."""
    rows = [f"{env} {name}" for env, steps in results.items()
            for (name, _, _), runs in zip(STEPS, steps, strict=True)
            if any(r["epochs"] != s.epochs_of(env) for r in runs)]  # fmt: skip
    if not rows:
        return ""
    return (f"Not yet at the epochs above (kept from an earlier budget; the last column says "
            f"how many): {', '.join(rows)}.\n")  # fmt: skip


def _versions(
    results: dict[str, list[list[dict]]], key: str, lead: str, what: str, fix: str
) -> str:
    """A note naming the code versions (``key``: a git SHA in the scores; rows scored before it
    was recorded: "before <key>") behind a column when there is more than one."""
    column = "t2_success" if key == "t2_git" else "grad_time"
    shas = {r[key][:7] if key in r else f"before {key}" for steps in results.values()
            for runs in steps for r in runs if column in r}  # fmt: skip
    if len(shas) < 2:
        return ""
    versions = ", ".join(sorted(shas))
    return (
        f"{lead} {len(shas)} {what} versions ({versions}): compare them within one version; "
        f"{fix}.\n"
    )


def notes(s: Settings, n_test: str, envs: tuple[str, ...]) -> str:
    epochs = ", ".join(f"{env} {s.epochs_of(env)}" for env in envs)
    return f"""
Notes: each step changes one field of the step above (`gdnplan.ablation.STEPS`). Every step
is trained from scratch on the same data (`data/<env>/train`, the shipped weights' share of
it) for the same number of Adam steps: {epochs} epochs (batch {s.batch}; early stopping
after {PATIENCE} epochs without a better validation MAE), with the paper's loss (squared
distance error only) and the same seeds; ± is the standard error over the seeds. Train s:
the CPU seconds those epochs took on one torch thread (the cost of a step's epochs).
MAE, AUC, ACD: the {n_test} samples of `data/<env>/test` (seed 1). d̂+∇: one batch of
{s.timing_batch} configurations of one scene, CPU time of the fastest of 5, one thread (the
default inference path: the compiled pass where it serves the network). Sweep max: the
largest change of d̂ between 0.003 rad steps along {s.sweep_steps}-step sweeps of every
joint from {s.sweeps} configuration(s), the largest over the seeds. Table II: Ipopt on the
environment's own reaching problems (b and d only), certified successes over all seeds, the
median wall time and the median CPU time of the planning process (the work: wall times of
rows scored while other jobs ran are longer; rows scored before it was recorded show "–").
"""
