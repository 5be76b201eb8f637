"""Metrics of a distance model against coal (Table I, paper §V-A), and one model's scores.

The metrics are pure functions of arrays (:mod:`gdnplan.train` applies them to the validation
set while training); :func:`evaluate_model` applies them to one model on the held-out test
split of an environment (``data/<env>/test``, seed 1, see :mod:`gdnplan.data`), so every method
sees the same configurations and obstacle sets. :mod:`gdnplan.evaluate` builds Table I from it.

Definitions (coal is the ground truth f):

* MAE = mean_i |d̂_i − f_i| (m), also reported as a fraction of the robot's reach.
* Welch's t-test between two absolute-error samples e₁, e₂ (unequal variances):
  t = (ē₁ − ē₂) / √(s₁²/n₁ + s₂²/n₂),  ν = (s₁²/n₁ + s₂²/n₂)² / Σ_k (s_k²/n_k)² / (n_k − 1),
  p = 2 · P(T_ν > |t|).
* AUC of the classification "collision ⇔ f ≤ margin": positives are coal collisions, the
  score is −d̂ (smaller predicted distance ⇒ more likely in collision); computed by the rank
  (Mann–Whitney) formula AUC = (R₊ − n₊(n₊ + 1)/2) / (n₊ n₋) with mid-ranks for ties.
* ACD = mean_i (1 − cos(∇d̂_i, ∇f_i)) over configurations where coal's gradient is non-zero;
  a zero model gradient counts as cos = 0 (distance 1).
"""

from __future__ import annotations

import hashlib
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Protocol, runtime_checkable

import numpy as np
from scipy import stats

from .data import DATA_DIR, SPLITS, Dataset, load, split_dir, split_samples
from .distance import signed_distance, signed_distance_and_grad
from .errors import InputError
from .models import DistanceModel


def mean_absolute_error(pred: np.ndarray, true: np.ndarray) -> float:
    """MAE (m) of predictions (B,) against ground truth (B,)."""
    pred, true = np.asarray(pred, float), np.asarray(true, float)
    if pred.shape != true.shape or pred.ndim != 1 or len(pred) == 0:
        raise InputError(
            f"pred/true: expected equal non-empty (B,) shapes, got {pred.shape}, {true.shape}"
        )
    return float(np.mean(np.abs(pred - true)))


def welch_p_value(a: np.ndarray, b: np.ndarray) -> float:
    """Two-sided p-value of Welch's t-test (unequal variances) between samples a and b."""
    return float(
        stats.ttest_ind(np.asarray(a, float), np.asarray(b, float), equal_var=False).pvalue
    )


def roc_auc(score: np.ndarray, positive: np.ndarray) -> float:
    """Area under the ROC curve by the rank formula (ties get mid-ranks, i.e. count ½).

    Args:
        score: (B,) larger = more likely positive.
        positive: (B,) bool labels.

    Returns:
        AUC in [0, 1]; NaN when one class is empty.
    """
    score, positive = np.asarray(score, float), np.asarray(positive, bool)
    n_pos, n_neg = int(positive.sum()), int((~positive).sum())
    if n_pos == 0 or n_neg == 0:
        return float("nan")
    ranks = stats.rankdata(score)  # average ranks for ties
    return float((ranks[positive].sum() - n_pos * (n_pos + 1) / 2) / (n_pos * n_neg))


def roc_curve(score: np.ndarray, positive: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """ROC points (false-positive rate, true-positive rate), each (K,), from (0,0) to (1,1).

    One point per distinct threshold (tied scores move both rates at once), so the trapezoid
    area under the curve equals :func:`roc_auc`.
    """
    score, positive = np.asarray(score, float), np.asarray(positive, bool)
    order = np.argsort(-score, kind="stable")
    s, y = score[order], positive[order]
    last = np.r_[np.flatnonzero(np.diff(s) != 0), len(s) - 1]  # end of each tie group
    tp = np.r_[0, np.cumsum(y)[last]]
    fp = np.r_[0, np.cumsum(~y)[last]]
    return fp / max(fp[-1], 1), tp / max(tp[-1], 1)


def cosine_distances(g_model: np.ndarray, g_true: np.ndarray) -> np.ndarray:
    """Per-row 1 − cos(g_model, g_true) for (B, n) arrays; a zero row has cos = 0."""
    a, b = np.asarray(g_model, float), np.asarray(g_true, float)
    na, nb = np.linalg.norm(a, axis=1), np.linalg.norm(b, axis=1)
    dot = np.einsum("ij,ij->i", a, b)
    cos = np.divide(dot, na * nb, out=np.zeros_like(dot), where=(na > 0) & (nb > 0))
    return 1.0 - cos


def used_cosine_distances(g_model: np.ndarray, g_true: np.ndarray) -> np.ndarray:
    """1 − cos(ĝ, g) (n_used,) over the rows where coal's gradient g is non-zero."""
    used = np.linalg.norm(np.asarray(g_true, float), axis=1) > 0
    return cosine_distances(g_model[used], g_true[used])


DEFAULT_MARGIN = 0.0  # m: collision ⇔ f ≤ margin


# -------------------------------------------------------------------- one model on a test set
def timed(fn: Callable[[], Any], repeats: int = 1) -> tuple[Any, float]:
    """Run ``fn`` ``repeats`` times; return its last result and the fastest wall time (s)."""
    best, out = np.inf, None
    for _ in range(repeats):
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
    return out, float(best)


# -------------------------------------------------------------------- test sets
def test_set(env: str, n: int = SPLITS["test"][1], root: Path | str = DATA_DIR) -> Dataset:
    """The first n samples of the held-out split of ``env`` (seed 1).

    Reads ``data/<env>/test`` when it holds at least n samples, otherwise labels them here with
    :func:`gdnplan.data.split_samples`, the routine ``gdnplan generate`` writes its shards with
    (the same samples either way).
    """
    path = split_dir(env, "test", root)
    if path.is_dir() and any(path.glob("shard_*.npz")):
        ds = load(path, n)
        if len(ds) >= n:
            return ds
    return split_samples(env, SPLITS["test"][0], 0, n)


def scene_groups(ds: Dataset) -> list[np.ndarray]:
    """Indices of samples sharing one obstacle set (one group for a/c, one per sample for b/d/e)."""
    key = np.ascontiguousarray(
        np.concatenate([ds.obstacles.reshape(len(ds), -1), ds.sizes.astype(float)], 1)
    )
    _, inverse = np.unique(key, axis=0, return_inverse=True)
    inverse = inverse.reshape(-1)
    return [np.flatnonzero(inverse == g) for g in range(inverse.max() + 1)]


@runtime_checkable
class DatasetModel(Protocol):
    """A model that predicts a whole dataset at once (each sample with its own obstacles)."""

    def predict_dataset(self, ds: Dataset, grad: bool) -> tuple[np.ndarray, np.ndarray | None]:
        """((B,), (B, dof) or None) predictions for every sample of ``ds``."""
        ...


def predict(model: DistanceModel, ds: Dataset, grad: bool) -> tuple[np.ndarray, np.ndarray | None]:
    """Predictions ((B,), (B, dof) or None) of any model on a dataset.

    Uses ``model.predict_dataset`` when the model has it; otherwise calls the model once per
    obstacle set (:func:`scene_groups`).
    """
    if isinstance(model, DatasetModel):
        return model.predict_dataset(ds, grad)
    d = np.empty(len(ds))
    g = np.empty(ds.q.shape) if grad else None
    for idx in scene_groups(ds):
        scene = ds.scene(int(idx[0]))
        if grad:
            d[idx], g[idx] = model.distance_and_grad(scene, ds.q[idx])
        else:
            d[idx] = model.distance(scene, ds.q[idx])
    return d, g


def coal_predict(ds: Dataset, grad: bool) -> tuple[np.ndarray, np.ndarray | None]:
    """coal on a dataset, one call per obstacle set (what the coal timing measures)."""
    d = np.empty(len(ds))
    g = np.empty(ds.q.shape) if grad else None
    for idx in scene_groups(ds):
        scene = ds.scene(int(idx[0]))
        if grad:
            d[idx], g[idx] = signed_distance_and_grad(scene, ds.q[idx])
        else:
            d[idx] = signed_distance(scene, ds.q[idx])
    return d, g


# -------------------------------------------------------------------- one model
@dataclass(frozen=True)
class Result:
    """One method on one environment.

    Attributes:
        method: display name.
        env: environment.
        n: samples in the timed batch and the AUC / MAE.
        seconds: wall time of the distance batch (s).
        mae: MAE (m), None for score models (DiffCo).
        mae_reach: MAE / reach of the robot, None for score models.
        auc: ROC AUC of f ≤ margin.
        acd: average cosine distance of ∂/∂q, over ``n_grad`` configurations.
        acd_se: its standard error s / √n_grad (a tail of near-opposite gradients dominates it).
        n_grad: configurations in the ACD.
        abs_error: (n,) |d̂ − f| (for Welch's test), None for score models.
        score: (n,) the model's output d̂ (for ROC curves and scatter plots).
    """

    method: str
    env: str
    n: int
    seconds: float
    mae: float | None
    mae_reach: float | None
    auc: float
    acd: float | None
    acd_se: float | None
    n_grad: int
    abs_error: np.ndarray | None
    score: np.ndarray


def evaluate_predictions(
    method: str,
    ds: Dataset,
    d_hat: np.ndarray,
    g_hat: np.ndarray | None,
    seconds: float,
    is_distance: bool,
    reach: float,
    margin: float = DEFAULT_MARGIN,
) -> Result:
    """Metrics of predictions d̂ (B,) and gradients (n_grad, dof) (first rows of ``ds``)."""
    err = np.abs(d_hat - ds.d) if is_distance else None
    mae = mean_absolute_error(d_hat, ds.d) if is_distance else None
    cd = None if g_hat is None else used_cosine_distances(g_hat, ds.grad[: len(g_hat)])
    return Result(
        method=method,
        env=ds.env,
        n=len(ds),
        seconds=seconds,
        mae=mae,
        mae_reach=None if mae is None else mae / reach,
        auc=roc_auc(-d_hat, ds.d <= margin),
        acd=None if cd is None else float(np.mean(cd)),
        acd_se=None if cd is None else float(stats.sem(cd)),
        n_grad=0 if cd is None else len(cd),
        abs_error=err,
        score=d_hat,
    )


def evaluate_model(
    model: DistanceModel,
    env: str,
    n: int = 5000,
    n_grad: int = 5000,
    ds: Dataset | None = None,
    margin: float = DEFAULT_MARGIN,
    repeats: int = 3,
) -> Result:
    """Time, MAE, AUC and ACD of one model on the first n test samples of ``env``.

    The time is the fastest of ``repeats`` wall times of ``distance`` over the whole batch (per
    obstacle set where the model has no ``predict_dataset``); gradients are taken on the first
    ``n_grad`` samples.
    Models with ``is_distance = False`` (scores, e.g. DiffCo) get no MAE.
    """
    ds = test_set(env, n) if ds is None else ds.subset(slice(0, n))
    (d_hat, _), seconds = timed(lambda: predict(model, ds, grad=False), repeats)
    _, g_hat = predict(model, ds.subset(slice(0, min(n_grad, len(ds)))), grad=True)
    reach = ds.scene(0).robot.reach
    return evaluate_predictions(
        getattr(model, "name", type(model).__name__),
        ds,
        d_hat,
        g_hat,
        seconds,
        bool(getattr(model, "is_distance", True)),
        reach,
        margin,
    )


def sha256_prefix(path: Path) -> str:
    """First 10 hex digits of a file's SHA-256."""
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()[:10]
