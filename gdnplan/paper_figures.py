"""The paper's figures from Table I's models: Fig. 5 (coal, DiffCo and GraphDistNet distance
fields over (q1, q2) of a 2-DoF environment, with a free detour path) and a Table I run's ROC
curves and predicted-vs-true scatter plots (:func:`table1_figures`)."""

from __future__ import annotations

import logging
import time
from pathlib import Path

import numpy as np

from .distance import signed_distance_and_grad
from .env_models import graphdistnet_of_env
from .flags import check_flag
from .metrics import DEFAULT_MARGIN, Result, roc_curve

log = logging.getLogger(__name__)


def detour_path(
    scene,
    start: np.ndarray,
    goal: np.ndarray,
    clearance: float = 0.05,
    steps: int = 200,
    waypoints: int = 60,
) -> np.ndarray:
    """A joint path (T, dof) from start to goal pushed out of collision along coal's gradient.

    Starts from the straight line and moves every waypoint closer than ``clearance`` (m) by
    0.05 rad along ∂f/∂q, then re-spaces the path evenly, ``steps`` times (for Fig. 5 only).
    """
    q = np.linspace(start, goal, waypoints)
    for _ in range(steps):
        d, g = signed_distance_and_grad(scene, q[1:-1])
        push = (d < clearance)[:, None] * g / np.maximum(np.linalg.norm(g, axis=1), 1e-9)[:, None]
        q[1:-1] += 0.05 * push
        arc = np.r_[0, np.cumsum(np.linalg.norm(np.diff(q, axis=0), axis=1))]
        t = np.linspace(0, arc[-1], waypoints)
        q = np.stack([np.interp(t, arc, q[:, j]) for j in range(q.shape[1])], 1)
    return q


def fig5(env: str = "a", grid: int = 101, diffco_train: int = 3000, progress: bool = False):
    """The paper's Fig. 5 for a 2-DoF environment: coal, DiffCo (score) and GraphDistNet fields.

    Returns the matplotlib Figure; GraphDistNet is left out when its weights are missing. With
    ``progress`` a tqdm bar on stderr counts the grid configurations evaluated.
    """
    from tqdm import tqdm

    from .models import CoalModel
    from .models.diffco import DiffCo
    from .scene import make_scene
    from .viz import distance_field, field_figure

    progress = check_flag(progress, "progress")
    scene = make_scene(env, seed=0)
    models = {"coal f (m)": CoalModel()}
    t0 = time.perf_counter()
    models["DiffCo score −s"] = DiffCo.train(scene, n=diffco_train)
    log.info("field: DiffCo trained on %d samples, %.2f s", diffco_train, time.perf_counter() - t0)
    gdn = graphdistnet_of_env(env)
    if gdn is not None:
        models["GraphDistNet d̂ (m)"] = gdn
    total = len(models) * grid * grid
    with tqdm(total=total, desc=f"field {env}", unit="q", disable=not progress) as bar:
        fields = {
            name: distance_field(model, scene, grid, progress=bar.update)
            for name, model in models.items()
        }
    path = detour_path(scene, np.array([1.3, 1.5]), np.array([1.3, -2.6]))
    return field_figure(scene, fields, path)


def table1_figures(results: dict[str, tuple[list[Result], float | None]], out_dir: Path) -> list:
    """ROC curves and predicted-vs-true scatter plots of a Table I run, written as PNGs."""
    from .viz import roc_figure, save_figure, scatter_figure

    curves, points = {}, {}
    for env, (rows, _) in results.items():
        truth = next(r.score for r in rows if r.method == "coal")
        curves[env] = {
            r.method: (*roc_curve(-r.score, truth <= DEFAULT_MARGIN), r.auc)
            for r in rows
            if r.method != "coal" and "w/ AL" not in r.method and r.score is not None
        }
        points[env] = {
            r.method: (truth[:1000], r.score[:1000]) for r in rows if r.abs_error is not None
        }
    out_dir.mkdir(parents=True, exist_ok=True)
    paths = [out_dir / "table1_roc.png", out_dir / "table1_scatter.png"]
    save_figure(roc_figure(curves), paths[0])
    save_figure(scatter_figure(points), paths[1])
    return paths


__all__ = ["detour_path", "fig5", "table1_figures"]
