"""What a training run reports: Table I metrics of a network on a held-out split, the git commit
of the source, the loss curve, and the weights file with its card.

Metrics (:func:`evaluate`, paper Table I), against coal labels on a held-out split:

* MAE = mean |d̂ − f| (m), also as a fraction of the arm's reach;
* AUC of the collision classifier d̂ ≤ margin vs f ≤ margin (Mann–Whitney rank formula);
* ACD = mean (1 − cos(∂d̂/∂q, ∂f/∂q)) over samples where coal's gradient is non-zero (a zero
  model gradient counts as cos = 0), as in :mod:`gdnplan.metrics`.
"""

from __future__ import annotations

import subprocess
import time
from pathlib import Path

import numpy as np

from ..data import Dataset
from ..files import atomic_path
from ..metrics import roc_auc, used_cosine_distances
from ..models.graphdistnet import GraphDistNet
from ..models.weights import write_weights
from .tensors import predict, tensors

SOURCE_ROOT = Path(__file__).resolve().parents[2]  # a git checkout, when not installed


def metrics(
    d_hat: np.ndarray, g_hat: np.ndarray, d: np.ndarray, g: np.ndarray, reach: float, margin: float
) -> dict:
    """MAE (m, fraction of reach), AUC of d ≤ margin, ACD; see the module docstring."""
    cd = used_cosine_distances(g_hat, g)
    mae = float(np.mean(np.abs(d_hat - d)))
    return {
        "n": len(d),
        "mae_m": mae,
        "mae_reach": mae / reach,
        "auc": roc_auc(-d_hat, d <= margin),
        "acd": float(np.mean(cd)),
        "acd_n": len(cd),
        "collision_fraction": float(np.mean(d <= margin)),
    }


def evaluate(net: GraphDistNet, ds: Dataset, margin: float = 0.0, device: str = "cpu") -> dict:
    """Table I metrics of ``net`` on a held-out split ``ds`` (all samples)."""
    t = tensors(ds)
    start = time.perf_counter()
    d_hat, g_hat = predict(net, t, device=device)
    elapsed = time.perf_counter() - start
    out = metrics(d_hat, g_hat, ds.d, ds.grad, t.graph.robot.reach, margin)
    out["seconds_per_sample_with_grad"] = elapsed / len(ds)
    return out


def git_sha() -> str:
    """The commit of gdnplan's source checkout, or "unknown" when installed from a wheel."""
    if not (SOURCE_ROOT / ".git").exists():
        return "unknown"
    try:
        return subprocess.run(
            ["git", "rev-parse", "HEAD"],
            cwd=SOURCE_ROOT,
            capture_output=True,
            text=True,
            check=True,
        ).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "unknown"


def save_weights(net: GraphDistNet, card: dict, path: Path | str) -> Path:
    """Write ``path`` (safetensors) and the JSON card beside it (the architecture as
    ``config``; the loss, when the card has one, stays in ``card["training"]["loss"]``)."""
    return write_weights(path, net.state_dict(), {**card, "config": net.config.to_dict()})


def plot_losses(log: list[dict], path: Path, title: str) -> None:
    """Training loss and validation MAE per epoch, as a PNG."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(5, 3.2))
    epochs = [e["epoch"] for e in log]
    ax.semilogy(epochs, [e["train_loss"] for e in log], label="train loss (normalised MSE)")
    ax.semilogy(epochs, [e["val_mae_m"] for e in log], label="validation MAE (m)")
    ax.set_xlabel("epoch")
    ax.set_title(title)
    ax.legend()
    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=100)
    plt.close(fig)
