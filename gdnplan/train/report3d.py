"""A GraphDistNet-3D network scored on a 3-D split, and a run's best state exported as weights.

:func:`evaluate3d` gives Table I's metrics (MAE (m), AUC of f ≤ 0, ACD;
:func:`gdnplan.train.report.metrics`) of a network on the first n samples of a split folder,
∂d̂/∂q through the node Jacobians; :func:`export_weights` writes a run's best state as
safetensors + JSON card with those metrics on a held-out folder.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import torch

from ..data.samples3d import env_robot3d
from ..graph3d import robot_graph3d
from ..models.graphdistnet3d import GraphDistNet3D, GraphDistNet3DConfig
from ..models.weights import read_card, write_weights
from .batch3d import make_batch
from .checkpoint import load_checkpoint
from .report import git_sha, metrics
from .shard_stream3d import read_shard, shard_files, split_env


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


__all__ = ["evaluate3d", "export_weights"]
