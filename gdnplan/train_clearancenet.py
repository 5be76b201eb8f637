"""Training of the ClearanceNet baseline (:mod:`gdnplan.models.clearancenet`, Table I).

Training (:func:`train`) minimises ((d̂ − f) / reach)² with Adam on the same ``data/<env>/train``
split as GraphDistNet (10 % held out for validation, learning rate halved after 3 epochs without
validation improvement, early stopping, wall-clock budget). It is a small loop of its own because
:mod:`gdnplan.train` builds graph tensors for GraphDistNet only. :func:`train_and_save` is
``gdnplan train --model clearancenet``: train, score on the test split, write weights + card.
"""

from __future__ import annotations

import math
import time
from pathlib import Path

import numpy as np
import torch

from .data import Dataset, load, split_dir
from .metrics import evaluate_model
from .models.clearancenet import (
    ClearanceNet,
    ClearanceNetConfig,
    ClearanceNetModel,
    obstacle_vector,
)


def train(
    env: str,
    train_set: Dataset,
    config: ClearanceNetConfig | None = None,
    batch: int = 256,
    lr: float = 1e-3,
    epochs: int = 200,
    patience: int = 10,
    time_budget: float | None = None,
    seed: int = 0,
) -> ClearanceNetModel:
    """Adam on ((d̂ − f)/scale)², best validation epoch kept (see the module docstring).

    Args:
        env: environment (sets the input layout unless ``config`` is given).
        train_set: training samples (10 % become the validation set).
        time_budget: stop after this many seconds of training (s).

    Returns:
        The trained model; its card records the data size, epochs, time and validation MAE.
    """
    config = config or ClearanceNetConfig.for_env(env)
    torch.manual_seed(seed)
    order = np.random.default_rng(seed).permutation(len(train_set))
    n_val = max(len(train_set) // 10, 1)
    obst = obstacle_vector(config, train_set.obstacles, train_set.sizes)
    q = torch.as_tensor(train_set.q, dtype=torch.float32)
    o = torch.as_tensor(obst, dtype=torch.float32)
    d = torch.as_tensor(train_set.d, dtype=torch.float32)
    val, tr = torch.as_tensor(order[:n_val]), torch.as_tensor(order[n_val:])
    net = ClearanceNet(config)
    opt = torch.optim.Adam(net.parameters(), lr=lr)
    best, best_state, stale, plateau, log = math.inf, None, 0, 0, []
    start = time.perf_counter()
    for epoch in range(epochs):
        if stale >= patience or (time_budget and time.perf_counter() - start > time_budget):
            break
        net.train()
        perm = tr[torch.as_tensor(np.random.default_rng([seed, epoch]).permutation(len(tr)))]
        for s in range(0, len(perm), batch):
            rows = perm[s : s + batch]
            loss = ((net(q[rows], o[rows]) - d[rows]) / config.scale).square().mean()
            opt.zero_grad()
            loss.backward()
            opt.step()
        net.eval()
        with torch.inference_mode():
            val_mae = float((net(q[val], o[val]) - d[val]).abs().mean())
        log.append({"epoch": epoch, "val_mae_m": val_mae, "lr": opt.param_groups[0]["lr"]})
        if val_mae < best:
            best, stale, plateau = val_mae, 0, 0
            best_state = {k: v.detach().clone() for k, v in net.state_dict().items()}
        else:
            stale, plateau = stale + 1, plateau + 1
            if plateau >= 3:
                plateau = 0
                for g in opt.param_groups:
                    g["lr"] /= 2
    net.load_state_dict(best_state)
    card = {
        "env": env,
        "data": {"train_dir": f"data/{env}/train", "n_train": len(tr), "n_val": n_val},
        "training": {
            "seed": seed,
            "batch": batch,
            "lr": lr,
            "epochs": len(log),
            "best_val_mae_m": best,
            "seconds": time.perf_counter() - start,
            "threads": torch.get_num_threads(),
        },
        "parameters": sum(p.numel() for p in net.parameters()),
    }
    return ClearanceNetModel(net, card)


def train_and_save(
    env: str, time_budget: float = 120.0, patience: int = 10, out: Path | str | None = None
) -> dict:
    """Train on ``data/<env>/train``, score on the test split, write ``weights/clearancenet_<env>``.

    Returns the card (training log summary and test metrics: n, MAE (m), AUC, ACD).
    """
    torch.set_num_threads(1)
    model = train(env, load(split_dir(env, "train")), patience=patience, time_budget=time_budget)
    r = evaluate_model(model, env, n=5000)
    model.card["test"] = {"n": r.n, "mae_m": r.mae, "auc": r.auc, "acd": r.acd, "n_grad": r.n_grad}
    model.card["command"] = (
        f"gdnplan train --model clearancenet --env {env} --time-budget {time_budget:g} "
        f"--patience {patience}"
    )
    model.save(out or Path("weights") / f"clearancenet_{env}.safetensors")
    return model.card
