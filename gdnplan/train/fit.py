"""The training loop of every learned model: :func:`fit` with its schedule :class:`FitConfig`.

A model supplies a :class:`Learner`: its network, the loss of a batch of training rows, and a
validation that scores the network (``val_score``, lower is better). :func:`fit` owns the rest:

* the validation split (:func:`validation_split`): a permutation of the n samples with the
  run's seed, the first max(⌊n/10⌋, 1) for validation, the others for training;
* epochs of Adam over a permutation of the training rows that is a function of (seed, epoch),
  in batches of ``batch``; a torch.Generator seeded seed · 100 003 + epoch is handed to the
  loss (GraphDistNet's random partners), so runs are deterministic on one device;
* learning-rate halving after ``PLATEAU`` epochs without a better validation score, early
  stopping after ``patience`` such epochs, an optional budget of training seconds (the epochs'
  own time, validation excluded; resumed runs count the time of the epochs before);
* the best-scoring state is kept and restored at the end (when fine-tuning the starting
  weights compete too: fine-tuning never returns worse weights than it started from);
* optionally a checkpoint (safetensors + JSON, :mod:`.checkpoint`) after every epoch, from which
  an interrupted run resumes where it stopped.
"""

from __future__ import annotations

import json
import math
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Protocol

import numpy as np
import torch
from tqdm import tqdm

from ..errors import InputError
from ..limits import check_int, is_number, shown
from .checkpoint import load_checkpoint, save_checkpoint

CLOCKS = {"wall": time.perf_counter, "cpu": time.process_time}  # FitConfig.budget_clock
PLATEAU = 3  # epochs without improvement before the learning rate is halved
COUNTS = {"batch": 1, "epochs": 1, "patience": 1, "seed": 0}  # integer fields: least value
# Adam moves every weight by about lr per step: nothing trains above ~1 (weights are O(1); a
# test wrecks a network with 50 on purpose), and past float32's range (3.4e38) torch's step
# raised "value cannot be converted to type float without overflow".
MAX_LR = 1e3


@dataclass(frozen=True)
class FitConfig:
    """The schedule of one training run (every learned model).

    Attributes:
        batch: samples per Adam step.
        lr: initial Adam learning rate (≥ 0; 0 keeps the starting weights).
        epochs: epoch cap (≥ 1).
        patience: early stopping after this many epochs without a better validation score.
        time_budget: stop once the epochs have trained this many seconds (s), or None.
        seed: the run's seed (initialisation, split, epoch order).
        device: ``"cpu"`` or ``"cuda"`` (``"cuda:k"``).
        budget_clock: how an epoch's seconds are counted: ``"wall"`` (elapsed time) or
            ``"cpu"`` (this process's CPU time: the same work whatever else runs on a shared
            machine; comparisons between runs use it).
    """

    batch: int = 256
    lr: float = 1e-3
    epochs: int = 200
    patience: int = 10
    time_budget: float | None = None
    seed: int = 0
    device: str = "cpu"
    budget_clock: str = "wall"

    def __post_init__(self) -> None:
        check_schedule(self)
        for name in COUNTS:  # numpy integers kept as ints (cards store them as JSON)
            object.__setattr__(self, name, int(getattr(self, name)))


def check_schedule(c: FitConfig) -> None:
    """InputError naming the first field of ``c`` that is not usable."""
    for name, least in COUNTS.items():
        check_int(getattr(c, name), name, least)
    check_lr(c.lr)
    budget = c.time_budget
    if budget is not None and not (is_number(budget) and math.isfinite(budget) and budget > 0):
        raise InputError(
            f"time_budget: expected a finite number of seconds > 0, got {shown(budget)}"
        )
    if c.budget_clock not in CLOCKS:
        raise InputError(f"budget_clock: expected one of {sorted(CLOCKS)}, got {c.budget_clock!r}")
    try:
        dev = torch.device(c.device)
    except (RuntimeError, TypeError) as e:
        raise InputError(f"device: expected cpu or cuda, got {c.device!r}") from e
    if dev.type not in ("cpu", "cuda"):
        raise InputError(f"device: expected cpu or cuda, got {c.device!r}")
    if dev.type == "cuda" and (dev.index or 0) >= torch.cuda.device_count():
        raise InputError(f"device: {c.device} is not available on this machine; use cpu")


def check_lr(lr: object, name: str = "lr") -> float:
    """``lr`` when it is a learning rate in [0, :data:`MAX_LR`], else InputError naming it."""
    if not (is_number(lr) and math.isfinite(lr) and 0 <= lr <= MAX_LR):
        raise InputError(
            f"{name}: expected a finite learning rate in [0, {MAX_LR:g}] (Adam steps every "
            f"weight by about lr; 1e-3 is the default), got {shown(lr)}"
        )
    return float(lr)


def validation_split(n: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """(training rows, validation rows) of n samples: a seeded permutation, 10 % (≥ 1) held out."""
    order = np.random.default_rng(seed).permutation(n)
    n_val = max(n // 10, 1)
    return order[n_val:], order[:n_val]


class Learner(Protocol):
    """What a model gives :func:`fit`."""

    net: torch.nn.Module  # its parameters are trained; its state_dict is what is kept

    def __len__(self) -> int:
        """Training samples (rows 0 … n − 1 of :meth:`loss`)."""
        ...

    def loss(self, rows: torch.Tensor, generator: torch.Generator) -> torch.Tensor:
        """The scalar loss of the training rows ``rows`` (network in training mode)."""
        ...

    def validate(self) -> dict:
        """Validation metrics, with ``val_score`` (lower is better) among them."""
        ...


def new_state(lr: float, settings: dict | None = None) -> dict:
    """The loop state before the first epoch (what a checkpoint stores)."""
    state = {"epoch": 0, "lr": lr, "best": math.inf, "stale": 0, "plateau": 0, "log": []}
    state["best_state"] = None
    if settings is not None:
        state["settings"] = settings
    return state


def _copy(net: torch.nn.Module) -> dict:
    return {k: v.detach().clone() for k, v in net.state_dict().items()}


def _epoch(
    learner: Learner, opt: torch.optim.Optimizer, c: FitConfig, epoch: int, desc: str | None
) -> float:
    """One pass of Adam over the training rows; returns Σ loss · batch size."""
    n = len(learner)
    learner.net.train()
    perm = torch.as_tensor(np.random.default_rng([c.seed, epoch]).permutation(n))
    gen = torch.Generator(device=c.device).manual_seed(c.seed * 100_003 + epoch)
    total = 0.0
    batches = range(0, n, c.batch)
    bar = tqdm(batches, desc=f"{desc} epoch {epoch}", leave=False, mininterval=5, disable=not desc)
    for s in bar:
        rows = perm[s : s + c.batch]
        loss = learner.loss(rows, gen)
        opt.zero_grad()
        loss.backward()
        opt.step()
        total += float(loss.detach()) * len(rows)
        bar.set_postfix(loss=f"{float(loss.detach()):.2e}", refresh=False)
    return total


def _select(state: dict, score: float, net: torch.nn.Module, opt: torch.optim.Optimizer) -> None:
    """Keep the best state; count stale epochs; halve the learning rate on a plateau."""
    if score < state["best"]:
        state.update(best=score, stale=0, plateau=0)
        state["best_state"] = _copy(net)
        return
    state["stale"] += 1
    state["plateau"] += 1
    if state["plateau"] >= PLATEAU:
        state["lr"] /= 2
        state["plateau"] = 0
        for g in opt.param_groups:
            g["lr"] = state["lr"]


def _start(
    learner: Learner,
    opt: torch.optim.Optimizer,
    state: dict,
    checkpoint: Path | None,
    start_weights: str | None,
    echo: Callable[[str], None],
) -> dict:
    """The state to continue from: the checkpoint's, or a new one (the start scored)."""
    if checkpoint is not None and checkpoint.exists():
        try:
            state = load_checkpoint(checkpoint, learner.net, opt)
        except RuntimeError as e:  # a checkpoint of another architecture, without settings
            raise InputError(
                f"resume: {checkpoint} does not fit this network "
                f"({' '.join(str(e).split())[:200]}); rerun with the run's options, or delete "
                "the checkpoint to start over"
            ) from e
        echo(f"resumed {checkpoint.parent} at epoch {state['epoch']}")
    elif start_weights is not None:
        state["init_val"] = learner.validate()
        state["best"] = state["init_val"]["val_score"]
        state["best_state"] = _copy(learner.net)
        echo(json.dumps({"init": start_weights, **state["init_val"]}))
    return state


def check_finite_epoch(entry: dict, checkpoint: Path | None) -> None:
    """InputError unless the epoch's training loss and validation score are finite: a run
    that diverged (a learning rate or loss weight too large) has NaN weights, which are
    neither kept nor checkpointed (the last checkpoint stays, from the last finite epoch)."""
    loss, score = entry["train_loss"], entry["val_score"]
    if math.isfinite(loss) and math.isfinite(score):
        return
    kept = ""
    if checkpoint is not None and checkpoint.exists():
        kept = f"; {checkpoint} keeps the last finite epoch"
    raise InputError(
        f"training diverged at epoch {entry['epoch']} (train_loss {loss}, val_score {score}): "
        f"lower the learning rate (--lr, now {entry['lr']:g}) or the loss weights (--set "
        f"grad_weight=…, contact_weight=…){kept}"
    )


def fit(
    learner: Learner,
    c: FitConfig,
    *,
    checkpoint: Path | None = None,
    settings: dict | None = None,
    start_weights: str | None = None,
    desc: str | None = None,
    echo: Callable[[str], None] | None = None,
) -> dict:
    """Train ``learner.net`` with the schedule ``c`` (module docstring); returns the state.

    Args:
        checkpoint: write a checkpoint there after every epoch, and resume from it when it
            exists (None: no checkpoint).
        settings: recorded in the checkpoint (checked on resume by the caller).
        start_weights: fine-tuning: the name of the weights ``learner.net`` starts from;
            they are scored first and kept unless an epoch beats them (None: a new network).
        desc: label of the progress bar (None: no bar).
        echo: called with one JSON line per epoch (None: silent).

    Returns:
        The loop state: ``log`` (one dict per epoch: train_loss, the validation metrics, lr,
        seconds, samples_per_s), ``best`` (the kept score), ``init_val`` (with
        ``start_weights``); ``learner.net`` holds the best state.
    """
    say = echo or (lambda _: None)
    opt = torch.optim.Adam(learner.net.parameters(), lr=c.lr)
    state = _start(learner, opt, new_state(c.lr, settings), checkpoint, start_weights, say)
    trained = sum(e["seconds"] for e in state["log"])
    n = len(learner)
    while state["epoch"] < c.epochs and state["stale"] < c.patience:
        if c.time_budget is not None and trained >= c.time_budget:
            break
        epoch = state["epoch"]
        clock = CLOCKS[c.budget_clock]
        start = clock()
        total = _epoch(learner, opt, c, epoch, desc)
        seconds = clock() - start
        trained += seconds
        val = learner.validate()
        entry = {"epoch": epoch, "train_loss": total / n, **val, "lr": state["lr"]}
        entry.update(seconds=seconds, samples_per_s=n / seconds)
        say(json.dumps(entry))
        check_finite_epoch(entry, checkpoint)
        state["log"].append(entry)
        _select(state, val["val_score"], learner.net, opt)
        state["epoch"] = epoch + 1
        if checkpoint is not None:
            save_checkpoint(checkpoint, learner.net, opt, state)
    if state["best_state"] is not None:  # None: no epoch ran and no starting weights
        learner.net.load_state_dict(state["best_state"])
    return state
