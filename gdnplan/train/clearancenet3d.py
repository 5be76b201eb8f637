"""Training the ClearanceNet-style 3-D baseline (:mod:`gdnplan.models.clearancenet3d`) on the
first n samples of a 3-D split, in memory (the MLP's inputs are small): Adam on the normalised
squared error ((d̂ − f) / scale)², batches of ``batch``, for ``seconds`` of training."""

from __future__ import annotations

import math
import time
from pathlib import Path

import numpy as np
import torch

from ..errors import InputError
from ..limits import check_int, is_number, shown
from ..models.clearancenet3d import ClearanceNet3D, ClearanceNet3DConfig, box_vector
from .fit import check_lr
from .graphdistnet3d import read_shard, shard_files
from .report import metrics


def load_arrays(folder: Path | str, n: int | None = None) -> dict[str, np.ndarray]:
    """q, obstacle vectors, d and grad of the first n samples of a 3-D split folder."""
    parts: dict[str, list] = {"q": [], "boxes": [], "d": [], "grad": []}
    total = 0
    for f in shard_files(folder):
        s = read_shard(f)
        boxes = box_vector(s["box_center"], s["box_size"])[s["scene"]]
        for k, v in (("q", s["q"]), ("boxes", boxes), ("d", s["d"]), ("grad", s["grad"])):
            parts[k].append(v)
        total += len(s["d"])
        if n is not None and total >= n:
            break
    return {k: np.concatenate(v)[:n] for k, v in parts.items()}


def train_clearancenet3d(
    data: dict,
    scale: float,
    seconds: float | None = None,
    batch: int = 512,
    lr: float = 1e-3,
    seed: int = 0,
    epochs: int | None = None,
) -> tuple[ClearanceNet3D, dict]:
    """Train the baseline on ``data`` (:func:`load_arrays`) for ``seconds`` of wall time or
    for exactly ``epochs`` epochs (reproducible whatever the machine's load; give one of the
    two); (net, summary)."""
    if (seconds is None) == (epochs is None):
        raise InputError("train_clearancenet3d: give either seconds or epochs")
    if epochs is not None:
        check_int(epochs, "epochs", 1)
    elif not (is_number(seconds) and math.isfinite(seconds) and seconds > 0):
        # nan trained nothing, inf for ever
        raise InputError(f"seconds: expected a finite number of seconds > 0, got {shown(seconds)}")
    check_int(batch, "batch", 1)
    check_int(seed, "seed", 0)
    check_lr(lr)
    torch.manual_seed(seed)
    net = ClearanceNet3D(ClearanceNet3DConfig(dof=data["q"].shape[1], scale=scale))
    q, o, d = (torch.as_tensor(data[k], dtype=torch.float32) for k in ("q", "boxes", "d"))
    opt = torch.optim.Adam(net.parameters(), lr=lr)
    gen = torch.Generator().manual_seed(seed)
    start, done = time.perf_counter(), 0
    while done < epochs if epochs is not None else time.perf_counter() - start < seconds:
        for rows in torch.randperm(len(d), generator=gen).split(batch):
            loss = ((net(q[rows], o[rows]) - d[rows]) / scale).square().mean()
            opt.zero_grad()
            loss.backward()
            opt.step()
        done += 1
    return net.eval(), {"epochs": done, "seconds": time.perf_counter() - start, "n": len(d)}


def evaluate_clearancenet3d(net: ClearanceNet3D, data: dict) -> dict:
    """Metrics (:func:`gdnplan.train.report.metrics`, margin 0) with ∂d̂/∂q by autograd."""
    q = torch.as_tensor(data["q"], dtype=torch.float32).requires_grad_(True)
    o = torch.as_tensor(data["boxes"], dtype=torch.float32)
    d = net(q, o)
    (g,) = torch.autograd.grad(d.sum(), q)
    return metrics(
        d.detach().double().numpy(),
        g.double().numpy(),
        data["d"],
        data["grad"],
        reach=net.config.scale,
        margin=0.0,
    )
