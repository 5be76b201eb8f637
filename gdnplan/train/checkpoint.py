"""Training checkpoints: the network, Adam's moments, the best state and the loop's state in one
safetensors + JSON pair (:mod:`gdnplan.models.weights`, sealed like weights), and the check that
a resumed run has the settings its checkpoint was started with."""

from __future__ import annotations

from pathlib import Path

import torch

from ..errors import InputError
from ..models.graphdistnet.config import REMOVED
from ..models.weights import read_weights, write_weights

RESUME_KEYS = ("config", "batch", "lr", "seed", "n_train", "extra")


def save_checkpoint(path: Path, net: torch.nn.Module, opt: torch.optim.Adam, state: dict) -> None:
    """Write ``net``'s tensors (``net.*``), Adam's state (``opt.<i>.*``), the best state
    (``best.*``) and the rest of ``state`` (the JSON card) to ``path``."""
    tensors = {f"net.{k}": v for k, v in net.state_dict().items()}
    params = [p for g in opt.param_groups for p in g["params"]]
    for i, p in enumerate(params):  # by parameter index: unused parameters have no state
        for k, v in opt.state.get(p, {}).items():
            tensors[f"opt.{i}.{k}"] = torch.as_tensor(v)
    best = state.pop("best_state", None)
    if best is not None:
        tensors.update({f"best.{k}": v for k, v in best.items()})
    try:
        write_weights(path, tensors, state, "checkpoint")
    finally:
        state["best_state"] = best  # None too: the loop reads the key after the epochs


def load_checkpoint(path: Path, net: torch.nn.Module, opt: torch.optim.Adam) -> dict:
    """Load the checkpoint ``path`` into ``net`` and ``opt``; returns the loop state."""
    tensors, state = read_weights(path, "checkpoint")
    net.load_state_dict({k[4:]: v for k, v in tensors.items() if k.startswith("net.")})
    params = [p for g in opt.param_groups for p in g["params"]]
    for i, p in enumerate(params):
        keys = {k.split(".", 2)[2]: v for k, v in tensors.items() if k.startswith(f"opt.{i}.")}
        if keys:
            opt.state[p] = keys
    for g in opt.param_groups:
        g["lr"] = state["lr"]
    best = {k[5:]: v for k, v in tensors.items() if k.startswith("best.")}
    state["best_state"] = best or None
    return state


def _without_removed(config: dict) -> dict:
    """``config`` without removed options at their former default (older checkpoints)."""
    return {k: v for k, v in config.items() if not (k in REMOVED and v == REMOVED[k])}


def check_resume(state: dict, settings: dict, ckpt: Path) -> None:
    """InputError naming the settings that differ from those the checkpoint's run started with
    (checkpoints written before settings were recorded are not checked)."""
    before = state.get("settings")
    if not isinstance(before, dict):
        return
    differ = sorted(k for k in settings if k in before and before[k] != settings[k])
    if "config" in differ:
        old, new = before["config"], settings["config"]
        old = _without_removed(old) if isinstance(old, dict) else {}
        keys = sorted(k for k in new.keys() | old.keys() if old.get(k) != new.get(k))
        differ = [k for k in differ if k != "config"] + [f"--set {k}" for k in keys]
    if differ:
        raise InputError(
            f"resume: {ckpt} was started with other settings ({', '.join(differ)}); rerun with "
            f"the same options, another --name / --run-dir, or delete the checkpoint to start over"
        )
