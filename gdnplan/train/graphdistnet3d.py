"""Training GraphDistNet-3D on shards it streams (:func:`train3d`), resumable from a checkpoint.

The training split is a folder of shards (:mod:`gdnplan.data.shards3d`); only one shard is in
memory at a time. Epoch e visits the shards in a permutation seeded by (seed, e) and the rows of
each shard in a permutation seeded by (seed, e, shard), in batches of ``batch`` rows (a shard's
last, shorter batch included). A batch's robot nodes and node Jacobians come from Pinocchio
(:meth:`~gdnplan.graph3d.RobotGraph3D.positions_and_jacobians`); the obstacle features are
computed once per scene of the batch (one-way cross edges) and handed to its rows. A
``ur5e_storage`` shard's rows have a robot graph each (fingers open or holding the stick:
:mod:`gdnplan.train.batch_storage3d`); the exported card names the validation split's env.

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
"""

from __future__ import annotations

import argparse
import json
import math
import time
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np
import torch

from ..arm3d.scene3d import workspace_radius
from ..data.samples3d import env_robot3d
from ..errors import InputError
from ..graph3d import point_cloud_graph, robot_graph3d
from ..models.graphdistnet3d import (
    GraphDistNet3D,
    GraphDistNet3DConfig,
    boxes_input,
    forward_with_grad,
    init_from_weights,
    obstacle_input,
    read_graphdistnet3d,
    robot_tensors,
)
from ..models.weights import read_card, write_weights
from .batch_storage3d import StorageBatch3D
from .checkpoint import load_checkpoint, save_checkpoint
from .loss import GraphDistNetLoss, distance_loss, gradient_loss
from .report import git_sha, metrics

CLOUD_K = 6  # neighbours of a point in a cloud's graph
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


def shard_files(folder: Path | str) -> list[Path]:
    files = sorted(p for p in Path(folder).glob("shard_*.npz") if not p.name.endswith(".tmp.npz"))
    if not files:
        raise InputError(f"data: no shards in {folder}; run `gdnplan generate --env ur5e_boxes`")
    return files


def read_shard(path: Path) -> dict:
    with np.load(path) as z:
        return {k: z[k] for k in z.files}


def batches(files: list[Path], batch: int, seed: int, epoch: int, skip: int = 0):
    """(step, shard arrays, rows) of one epoch (module docstring), from step ``skip`` on."""
    order = np.random.default_rng([seed, epoch]).permutation(len(files))
    step = 0
    for f in order:
        shard = None
        n = int(np.load(files[f])["d"].shape[0]) if step + 1 <= skip else None
        if n is not None:
            count = -(-n // batch)
            if step + count <= skip:
                step += count
                continue
        shard = read_shard(files[f])
        perm = np.random.default_rng([seed, epoch, int(f)]).permutation(len(shard["d"]))
        for s in range(0, len(perm), batch):
            if step >= skip:
                yield step, shard, perm[s : s + batch]
            step += 1


class Batch3D:
    """Model inputs of some rows of a shard (float32 tensors)."""

    def __init__(self, graph, shard: dict, rows: np.ndarray):
        q = shard["q"][rows]
        nodes, jac = graph.positions_and_jacobians(q)
        scenes, inverse = np.unique(shard["scene"][rows], return_inverse=True)
        self.nodes = torch.as_tensor(nodes, dtype=torch.float32)
        self.jac = torch.as_tensor(jac, dtype=torch.float32)
        if "points" in shard:  # ur5e_cloud: the kNN graph of every scene's cloud
            graphs = [point_cloud_graph(shard["points"][s], CLOUD_K) for s in scenes]
            self.obstacles = obstacle_input(graphs)
        else:
            self.obstacles = boxes_input(shard["box_center"][scenes], shard["box_size"][scenes])
        self.scene_rows = torch.as_tensor(inverse.reshape(-1), dtype=torch.long)
        self.d = torch.as_tensor(shard["d"][rows], dtype=torch.float32)
        self.grad = torch.as_tensor(shard["grad"][rows], dtype=torch.float32)

    def run(self, net: GraphDistNet3D, graph, create_graph: bool):
        """d̂ (B,) and ∂d̂/∂q (B, dof); ``create_graph`` to train on the gradient."""
        feats = net.obstacle_pass(self.obstacles).take(self.scene_rows)
        return forward_with_grad(net, graph, self.nodes, self.jac, feats, create_graph)

    def distance(self, net: GraphDistNet3D, graph) -> torch.Tensor:
        """d̂ (B,) alone (training on the distance loss only: no double backward)."""
        feats = net.obstacle_pass(self.obstacles).take(self.scene_rows)
        nbr, nbr_mask = robot_tensors(graph)
        return net(self.nodes, nbr, nbr_mask, feats)


def make_batch(graph, shard: dict, rows: np.ndarray, rim: int):
    """The batch of some rows of a shard: :class:`Batch3D` with the robot ``graph``, or for a
    ``ur5e_storage`` shard (robot variants) a :class:`StorageBatch3D` (a robot graph per row)."""
    if "variant" in shard:
        return StorageBatch3D(rim, shard, rows)
    return Batch3D(graph, shard, rows)


def split_env(folder: Path | str) -> str:
    """The environment of a split folder (its first shard's ``env``)."""
    return str(read_shard(shard_files(folder)[0])["env"])


def evaluate3d(net: GraphDistNet3D, folder: Path | str, n: int | None = None, chunk: int = 200):
    """Metrics (:func:`gdnplan.train.report.metrics`, margin 0) of ``net`` on the first n samples
    of a split folder, against its coal labels, with ∂d̂/∂q through the node Jacobians."""
    net.eval()
    graph = robot_graph3d(env_robot3d("ur5e_boxes"), net.config.rim)
    d_hat, g_hat, d, g = [], [], [], []
    taken = 0
    for f in shard_files(folder):
        shard = read_shard(f)
        m = len(shard["d"]) if n is None else min(len(shard["d"]), n - taken)
        for s in range(0, m, chunk):
            b = make_batch(graph, shard, np.arange(s, min(s + chunk, m)), net.config.rim)
            dh, gh = b.run(net, graph, False)
            d_hat.append(dh.detach().double().numpy())
            g_hat.append(gh.detach().double().numpy())
            d.append(b.d.double().numpy())
            g.append(b.grad.double().numpy())
        taken += m
        if n is not None and taken >= n:
            break
    net.train()
    arrays = [np.concatenate(x) for x in (d_hat, g_hat, d, g)]
    return metrics(*arrays, reach=net.config.scale, margin=0.0)


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


def export_weights(
    run_dir: Path | str, out: Path | str, val_dir: Path | str, n_test: int | None = None
) -> dict:
    """Write the run's best state as weights + card with its measured metrics on ``val_dir``."""
    run_dir = Path(run_dir)
    ckpt = run_dir / "checkpoint.safetensors"
    card = read_card(ckpt, "checkpoint")
    network = GraphDistNet3DConfig.from_dict(card["settings"]["network"])
    net = GraphDistNet3D(network)
    opt = torch.optim.Adam(net.parameters())
    state = load_checkpoint(ckpt, net, opt)
    if state.get("best_state"):
        net.load_state_dict(state["best_state"])
    test = evaluate3d(net, val_dir, n_test)
    out_card = {
        "model": "graphdistnet3d",
        "env": split_env(val_dir),
        "robot": "ur5e",
        "training": {k: state[k] for k in ("epoch", "step", "samples", "seconds", "best")},
        "settings": card["settings"],
        "test": {"dir": str(val_dir), **test},
        "acceptance": {
            "auc_min": 0.99,
            "acd_max": 0.35,
            "met": bool(test["auc"] >= 0.99 and test["acd"] <= 0.35),
        },
        "git_sha": git_sha(),
        "config": network.to_dict(),
    }
    write_weights(Path(out), net.state_dict(), out_card)
    return out_card


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


if __name__ == "__main__":
    main()
