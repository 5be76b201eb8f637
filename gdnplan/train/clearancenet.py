"""Training of the ClearanceNet baseline (:mod:`gdnplan.models.clearancenet`, Table I).

:func:`train` minimises ((d̂ − f) / reach)² with the shared loop :func:`gdnplan.train.fit.fit`
(the same validation split, learning-rate halving, early stopping, time budget and best-state
keeping as GraphDistNet), selecting by the validation MAE (m). :func:`train_and_score` is
``gdnplan train --model clearancenet``: train on ``data/<env>/train``, score on the test split,
write weights + card.
"""

from __future__ import annotations

import time
import warnings
from pathlib import Path

import torch

from ..data import DATA_DIR, Dataset, load, split_dir
from ..metrics import evaluate_model, test_set
from ..models.clearancenet import (
    ClearanceNet,
    ClearanceNetConfig,
    ClearanceNetModel,
    obstacle_vector,
)
from .fit import FitConfig, fit, validation_split
from .graphdistnet import check_env

TEST_SAMPLES = 5000  # the test split's samples the card's metrics use


class ClearanceNetLearner:
    """ClearanceNet's part of :func:`~gdnplan.train.fit.fit`: inputs (q, φ(O)) and labels f of
    the training and validation rows as tensors on ``device``."""

    def __init__(self, net: ClearanceNet, ds: Dataset, tr, val, device: str = "cpu"):
        obst = obstacle_vector(net.config, ds.obstacles, ds.sizes)
        q = torch.as_tensor(ds.q, dtype=torch.float32)
        o = torch.as_tensor(obst, dtype=torch.float32)
        d = torch.as_tensor(ds.d, dtype=torch.float32)
        tr, val = torch.as_tensor(tr), torch.as_tensor(val)
        self.net = net.to(device)
        self.train_part = tuple(x[tr].to(device) for x in (q, o, d))
        self.val_part = tuple(x[val].to(device) for x in (q, o, d))

    def __len__(self) -> int:
        return len(self.train_part[0])

    def loss(self, rows: torch.Tensor, generator: torch.Generator) -> torch.Tensor:
        q, o, d = (x[rows.to(x.device)] for x in self.train_part)
        return ((self.net(q, o) - d) / self.net.config.scale).square().mean()

    def validate(self) -> dict:
        q, o, d = self.val_part
        self.net.eval()
        with torch.inference_mode():
            mae = float((self.net(q, o) - d).abs().mean())
        return {"val_mae_m": mae, "val_score": mae}


def train(
    env: str,
    train_set: Dataset,
    config: ClearanceNetConfig | None = None,
    fit_config: FitConfig | None = None,
    **legacy,
) -> ClearanceNetModel:
    """Train ClearanceNet on ``train_set`` (10 % become the validation set) with the schedule
    ``fit_config`` (module docstring).

    Args:
        env: environment (sets the input layout unless ``config`` is given).
        config: the architecture (default: the paper's for ``env``).
        fit_config: the schedule (default :class:`FitConfig`). The old keywords (``batch=``,
            ``lr=``, ``epochs=``, ``patience=``, ``time_budget=``, ``seed=``) still work,
            deprecated.

    Returns:
        The trained model (on the CPU); its card records the data size, epochs, time and the
        validation MAE.
    """
    if legacy:
        warnings.warn(
            "train_clearancenet.train(…, batch=…, lr=…) is deprecated; pass "
            "fit_config=gdnplan.train.FitConfig(…)",
            DeprecationWarning,
            stacklevel=2,
        )
        fit_config = FitConfig(**legacy)
    c = fit_config or FitConfig()
    config = config or ClearanceNetConfig.for_env(env)
    torch.manual_seed(c.seed)
    tr, val = validation_split(len(train_set), c.seed)
    learner = ClearanceNetLearner(ClearanceNet(config), train_set, tr, val, c.device)
    start = time.perf_counter()
    state = fit(learner, c)
    net = learner.net.cpu().eval()
    card = {
        "env": env,
        "data": {"train_dir": f"data/{env}/train", "n_train": len(tr), "n_val": len(val)},
        "training": {
            "seed": c.seed,
            "batch": c.batch,
            "lr": c.lr,
            "epochs": len(state["log"]),
            "best_val_mae_m": state["best"],
            "seconds": time.perf_counter() - start,
            "threads": torch.get_num_threads(),
        },
        "parameters": sum(p.numel() for p in net.parameters()),
    }
    if c.device != "cpu":
        card["training"]["device"] = c.device
    return ClearanceNetModel(net, card)


def train_and_score(
    env: str,
    fit_config: FitConfig,
    out: Path | str | None = None,
    n_train: int | None = None,
    data_root: Path | str = DATA_DIR,
    command: str | None = None,
) -> dict:
    """Train on ``<data_root>/<env>/train`` (its first ``n_train`` samples), score on the
    first 5 000 test samples, write ``out`` (default ``weights/clearancenet_<env>``) + card.

    Returns the card (training summary and test metrics: n, MAE (m), AUC, ACD).
    """
    train_dir = split_dir(env, "train", data_root)
    model = train(env, check_env(load(train_dir, n_train), env, train_dir), fit_config=fit_config)
    ds = test_set(env, TEST_SAMPLES, data_root)
    r = evaluate_model(model, env, n=TEST_SAMPLES, ds=ds)
    model.card["test"] = {"n": r.n, "mae_m": r.mae, "auc": r.auc, "acd": r.acd, "n_grad": r.n_grad}
    if command is not None:
        model.card["command"] = command
    model.save(out or Path("weights") / f"clearancenet_{env}.safetensors")
    return model.card


def train_and_save(
    env: str, time_budget: float = 120.0, patience: int = 10, out: Path | str | None = None
) -> dict:
    """:func:`train_and_score` with the shipped weights' schedule (one torch thread)."""
    torch.set_num_threads(1)
    command = (
        f"gdnplan train --model clearancenet --env {env} --time-budget {time_budget:g} "
        f"--patience {patience}"
    )
    schedule = FitConfig(time_budget=time_budget, patience=patience)
    return train_and_score(env, schedule, out, command=command)
