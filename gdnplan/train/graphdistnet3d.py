"""Training GraphDistNet-3D on shards it streams (:func:`train3d`), resumable from a checkpoint.

The training split is a folder of shards (:mod:`gdnplan.data.shards3d`) streamed one at a time,
each epoch in a seeded order of shards and rows. A batch's robot nodes and node Jacobians come
from Pinocchio, its obstacle features once per scene of the batch; a ``ur5e_storage`` shard's
rows have a robot graph each. The exported card names the validation split's env.

Loss: :mod:`gdnplan.train.loss` (normalised squared error, contact weight, gradient cosine).
After every ``validate_every`` steps the network is scored on the first ``n_val`` samples of
the validation folder (MAE (m), AUC of f ≤ 0, ACD; :func:`gdnplan.train.report.metrics`), the
learning rate is halved after ``PLATEAU`` validations without a better MAE, the best state is
kept, and a checkpoint (network, Adam, best state, position in the epoch, log) is written, so
an interrupted run resumes at its last validation with the same command.

``--init WEIGHTS`` starts a new run's network from a weights file (its card's architecture, its
tensors; :func:`~gdnplan.models.graphdistnet3d.init_from_weights`) instead of a random draw,
with a fresh optimiser and learning-rate schedule; ``--min-readout`` adds the soft-minimum
readout (:class:`~gdnplan.models.graphdistnet3d.GraphDistNet3DConfig`), whose new parameters
start so that d̂ is the initial network's.

    python -m gdnplan.train.graphdistnet3d --train data/ur5e_boxes/train \\
        --val data/ur5e_boxes/test --run-dir runs/ur5e_boxes-3d [--time-budget S] \\
        [--init weights/ur5e_boxes3d_preliminary.safetensors] [--lr 3e-4] [--min-readout]

Modules: the shards' files, arrays and an epoch's batches in :mod:`.shard_stream3d`, a batch's
model inputs in :mod:`.batch3d`, the metrics on a split and the exported weights in
:mod:`.report3d`; this module runs the training loop and the command line, and re-exports
their names.
"""

from __future__ import annotations

import argparse
import json
import math
import time
from dataclasses import asdict, dataclass
from pathlib import Path

import torch

from ..arm3d.scene3d import workspace_radius
from ..data.samples3d import env_robot3d
from ..errors import InputError
from ..graph3d import robot_graph3d
from ..limits import MAX_SEED, check_int, is_number, shown
from ..models.fields import check_real
from ..models.graphdistnet3d import (
    GraphDistNet3D,
    GraphDistNet3DConfig,
    init_from_weights,
    read_graphdistnet3d,
)
from ..models.weights import read_card
from .batch3d import CLOUD_K, Batch3D, make_batch
from .checkpoint import load_checkpoint, save_checkpoint
from .fit import check_lr
from .loss import GraphDistNetLoss, distance_loss, gradient_loss
from .report3d import evaluate3d, export_weights
from .shard_stream3d import batches, read_shard, shard_files, split_env

PLATEAU = 20  # validations without a better MAE before the learning rate is halved


@dataclass(frozen=True)
class Train3DConfig:
    """Settings of a run (a resumed run must have the same ones, but the time budget)."""

    batch: int = 128
    lr: float = 1e-3
    min_lr: float = 1e-5
    seed: int = 0
    n_val: int = 500
    validate_every: int = 10
    grad_weight: float = 0.1
    contact_weight: float = 2.0
    contact_scale: float = 0.02

    def __post_init__(self) -> None:
        """InputError naming the first unusable field: counts are integers ≥ 1 (seed ≥ 0),
        0 ≤ min_lr ≤ lr ≤ MAX_LR, weights ≥ 0 and contact_scale > 0, all finite."""
        for name in ("batch", "n_val", "validate_every"):
            check_int(getattr(self, name), name, 1)
        check_int(self.seed, "seed", 0, MAX_SEED)
        check_lr(self.lr)
        check_real("min_lr", self.min_lr, 0.0, self.lr)
        for name in ("grad_weight", "contact_weight"):
            check_real(name, getattr(self, name), 0.0, 1e6)
        check_real("contact_scale", self.contact_scale, 1e-6, 1e3, " m")


def network_config(init: Path | str | None = None, min_readout: bool = False):
    """The architecture of a new run: the card's of the weights ``init`` (None: the default,
    scaled by the UR5e's reach), with the soft-minimum readout if ``min_readout``."""
    if init is None:
        network = GraphDistNet3DConfig(scale=round(workspace_radius(env_robot3d("ur5e_boxes")), 6))
    else:
        network = GraphDistNet3DConfig.from_dict(read_graphdistnet3d(init)[1]["config"])
    return network.with_(min_readout=True) if min_readout else network


def train3d(
    train_dir: Path | str,
    val_dir: Path | str,
    run_dir: Path | str,
    config: Train3DConfig = Train3DConfig(),
    network: GraphDistNet3DConfig | None = None,
    time_budget: float | None = None,
    echo=print,
    init: Path | str | None = None,
) -> dict:
    """Train (or resume) a run in ``run_dir`` for ``time_budget`` seconds (None: until the
    learning rate falls below ``min_lr``); returns the loop state (log, best, position). A new
    run's network starts from the weights ``init`` (:func:`init_from_weights`) if given."""
    if time_budget is not None and not (is_number(time_budget) and 0 <= time_budget < math.inf):
        raise InputError(f"time_budget: expected seconds ≥ 0 or None, got {shown(time_budget)}")
    if config.min_lr == 0 and time_budget is None:  # the halved rate reaches 0, and 0 ≥ 0
        raise InputError("min_lr: 0 never ends a run without a time budget; give one or min_lr > 0")
    torch.set_num_threads(1)
    run_dir = Path(run_dir)
    run_dir.mkdir(parents=True, exist_ok=True)
    robot = env_robot3d("ur5e_boxes")
    if network is None:
        network = network_config(init)
    shard_files(train_dir)
    shard_files(val_dir)
    graph = robot_graph3d(robot, network.rim)
    loss_cfg = GraphDistNetLoss(
        grad_weight=config.grad_weight,
        contact_weight=config.contact_weight,
        contact_scale=config.contact_scale,
    )
    torch.manual_seed(config.seed)
    net = GraphDistNet3D(network)
    opt = torch.optim.Adam(net.parameters(), lr=config.lr)
    ckpt = run_dir / "checkpoint.safetensors"
    settings = {"train": asdict(config), "network": network.to_dict(), "train_dir": str(train_dir)}
    if init is not None:
        settings["init"] = str(init)
    state = {
        "n_files": 0,
        "epoch": 0,
        "step": 0,
        "lr": config.lr,
        "best": math.inf,
        "bad": 0,
        "log": [],
        "seconds": 0.0,
        "samples": 0,
        "settings": settings,
    }
    if ckpt.exists():
        before = read_card(ckpt, "resume").get("settings")
        if json.loads(json.dumps(settings)) != before:
            raise InputError(
                f"resume: {ckpt} was started with other settings; use another --run-dir"
            )
        state = load_checkpoint(ckpt, net, opt)
        echo(f"resumed {ckpt}: epoch {state['epoch']} step {state['step']}")
    elif init is not None:
        fresh = init_from_weights(net, init)
        echo(f"started from {init}" + (f"; new parameters {fresh}" if fresh else ""))
    best_state = state.pop("best_state", None)
    start = time.perf_counter()
    spent0 = state["seconds"]
    while state["lr"] >= config.min_lr:
        if state["step"] == 0:  # a new epoch sees every complete shard written so far
            state["n_files"] = len(shard_files(train_dir))
        files = shard_files(train_dir)[: state.get("n_files") or None]
        for step, shard, rows in batches(
            files, config.batch, config.seed, state["epoch"], state["step"]
        ):
            b = make_batch(graph, shard, rows, network.rim)
            if config.grad_weight > 0:
                d_hat, g_hat = b.run(net, graph, True)
                loss = distance_loss(d_hat, b.d, loss_cfg, network.scale)
                loss = loss + gradient_loss(g_hat, b.grad, loss_cfg, network.scale)
            else:
                loss = distance_loss(b.distance(net, graph), b.d, loss_cfg, network.scale)
            opt.zero_grad()
            loss.backward()
            opt.step()
            state["step"], state["samples"] = step + 1, state["samples"] + len(rows)
            if (step + 1) % config.validate_every == 0:
                state["seconds"] = spent0 + time.perf_counter() - start
                best_state = _validate(
                    net, opt, val_dir, config, state, best_state, float(loss.detach()), echo
                )
                _save(ckpt, net, opt, state, best_state)
                if time_budget is not None and time.perf_counter() - start > time_budget:
                    return state
                if state["lr"] < config.min_lr:
                    break
        else:
            state["epoch"], state["step"] = state["epoch"] + 1, 0
    return state


def _validate(net, opt, val_dir, config, state, best_state, loss, echo):
    m = evaluate3d(net, val_dir, config.n_val)
    entry = {
        "epoch": state["epoch"],
        "step": state["step"],
        "samples": state["samples"],
        "seconds": state["seconds"],
        "train_loss": loss,
        "lr": state["lr"],
        **m,
    }
    state["log"].append(entry)
    echo(json.dumps(entry))
    if m["mae_m"] < state["best"]:
        state["best"], state["bad"] = m["mae_m"], 0
        return {k: v.detach().clone() for k, v in net.state_dict().items()}
    state["bad"] += 1
    if state["bad"] >= PLATEAU:
        state["lr"], state["bad"] = state["lr"] / 2, 0
        for g in opt.param_groups:
            g["lr"] = state["lr"]
    return best_state


def _save(ckpt, net, opt, state, best_state) -> None:
    save_checkpoint(ckpt, net, opt, {**state, "best_state": best_state})


def main(argv: list[str] | None = None) -> None:
    p = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    p.add_argument("--train", type=Path, default=Path("data/ur5e_boxes/train"))
    p.add_argument("--val", type=Path, default=Path("data/ur5e_boxes/test"))
    p.add_argument("--run-dir", type=Path, default=Path("runs/ur5e_boxes-3d"))
    p.add_argument("--time-budget", type=float, default=None, help="seconds of this invocation")
    p.add_argument("--export", type=Path, default=None, help="write the best weights + card here")
    p.add_argument("--lr", type=float, default=Train3DConfig.lr, help="initial learning rate")
    p.add_argument(
        "--validate-every",
        type=int,
        default=Train3DConfig.validate_every,
        help="training steps between validations (and checkpoints)",
    )
    p.add_argument("--init", type=Path, default=None, help="start the network from these weights")
    p.add_argument(
        "--min-readout", action="store_true", help="add the soft-minimum readout over robot nodes"
    )
    p.add_argument(
        "--grad-weight",
        type=float,
        default=Train3DConfig.grad_weight,
        help="λ of the gradient-cosine loss (0: distance loss only, no double backward)",
    )
    a = p.parse_args(argv)
    if a.export is not None:
        print(json.dumps(export_weights(a.run_dir, a.export, a.val)["test"], indent=1))
        return
    config = Train3DConfig(lr=a.lr, grad_weight=a.grad_weight, validate_every=a.validate_every)
    network = network_config(a.init, a.min_readout)
    train3d(a.train, a.val, a.run_dir, config, network, a.time_budget, init=a.init)


__all__ = [
    "CLOUD_K",
    "PLATEAU",
    "Batch3D",
    "Train3DConfig",
    "batches",
    "evaluate3d",
    "export_weights",
    "main",
    "make_batch",
    "network_config",
    "read_shard",
    "shard_files",
    "split_env",
    "train3d",
]


if __name__ == "__main__":
    main()
