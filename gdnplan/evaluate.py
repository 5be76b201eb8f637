"""Table I (paper §V-A): time, MAE with Welch's t-test, ROC AUC and ACD of every method on
every environment, the paper's figures beside them (Fig. 5 and the ROC/scatter plots:
:mod:`gdnplan.paper_figures`, re-exported here).

The metrics and one model's scores on the held-out test split (:func:`evaluate_model`,
``data/<env>/test``, seed 1, the same configurations and obstacle sets for every method) are
:mod:`gdnplan.metrics`, re-exported here.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from .assets import WEIGHTS_DIR
from .data import Dataset
from .distance import signed_distance_and_grad
from .env_models import BatchedGraphDistNet as BatchedGraphDistNet
from .env_models import clearancenet_of_env
from .env_models import graphdistnet_of_env as graphdistnet_of_env
from .env_models import load_clearancenet as load_clearancenet  # deprecated names
from .env_models import load_graphdistnet as load_graphdistnet
from .metrics import DEFAULT_MARGIN as DEFAULT_MARGIN
from .metrics import DatasetModel as DatasetModel
from .metrics import (  # moved to gdnplan.metrics; the `x as x` names are re-exported
    Result,
    coal_predict,
    evaluate_model,
    evaluate_predictions,
    predict,
    sha256_prefix,
    test_set,
    timed,
)
from .metrics import cosine_distances as cosine_distances
from .metrics import mean_absolute_error as mean_absolute_error
from .metrics import roc_auc as roc_auc
from .metrics import roc_curve as roc_curve
from .metrics import scene_groups as scene_groups
from .metrics import used_cosine_distances as used_cosine_distances
from .metrics import welch_p_value as welch_p_value
from .paper_figures import detour_path as detour_path  # moved; re-exported
from .paper_figures import fig5 as fig5
from .paper_figures import table1_figures as table1_figures
from .table1_rows import DRAWS, GDN, GRAPHDISTNET_FILES, PAPER_ROW, welch_p
from .table1_rows import FAITHFUL as FAITHFUL  # moved to table1_rows; re-exported
from .table1_rows import FAITHFUL_DRAWS as FAITHFUL_DRAWS
from .table1_rows import FAITHFUL_MEAN as FAITHFUL_MEAN
from .table1_rows import PAPER as PAPER
from .table1_rows import PAPER_P as PAPER_P
from .table1_text import NOTES as NOTES
from .table1_text import network_line as network_line
from .table1_text import networks_notes as networks_notes
from .table1_text import table1_markdown as table1_markdown

log = logging.getLogger(__name__)

# -------------------------------------------------------------------- Table I
ENVS = ("a", "b", "c", "d", "e")
DIFFCO_SOURCE = {"b": "a", "d": "c"}  # random env -> fixed env DiffCo is trained on (paper)
DIFFCO_OWN_SCENE = ("a", "c")  # fixed environments: DiffCo is scored in its training scene


@dataclass(frozen=True)
class TableSettings:
    """Sizes of one Table I run.

    Attributes:
        n: held-out samples per environment (time, MAE, AUC).
        n_grad: samples for the ACD.
        diffco_train: DiffCo training configurations (2-DoF, 7-DoF).
        al_scenes: test scenes DiffCo adapts to (active learning), per random environment.
        al_queries: configurations evaluated in each adapted scene.
        al_explore: uniform samples per active-learning update (besides 2 per support point).
    """

    n: int = 5000
    n_grad: int = 5000
    diffco_train: tuple[int, int] = (3000, 5000)
    al_scenes: int = 10
    al_queries: int = 200
    al_explore: int = 2000

    @classmethod
    def fast(cls) -> TableSettings:
        return cls(
            n=200, n_grad=100, diffco_train=(400, 600), al_scenes=1, al_queries=100, al_explore=300
        )


def diffco_rows(env: str, ds: Dataset, s: TableSettings) -> list[Result]:
    """DiffCo on ``env``: the score for time and AUC, the fitted surrogate for the ACD.

    Fixed environments (a, c) train on their own scene. Random ones (b, d, e) use a model
    trained on a (b), c (d) or one e scene (e) as is ("w/o AL": the stale layout, asked for
    with :meth:`~gdnplan.models.diffco.DiffCo.ignoring_obstacles`) and, on the scenes of the
    first ``al_scenes`` test samples, after active learning ("w/ AL"); the latter's AUC and ACD pool
    ``al_queries`` uniform configurations per adapted scene, and its time is the mean
    adaptation time per scene × n (the paper adapts to each test scene).
    """
    from .models.diffco import DiffCo
    from .scene import make_scene

    source = make_scene(DIFFCO_SOURCE.get(env, env), seed=0)
    n_train = s.diffco_train[0 if source.robot.dof == 2 else 1]
    base = DiffCo.train(source, n=n_train, seed=0)
    reach = source.robot.reach
    own = env in DIFFCO_OWN_SCENE
    scored = base if own else base.ignoring_obstacles()  # w/o AL: the training layout's score
    grad_ds = ds.subset(slice(0, s.n_grad))
    (d_hat, _), seconds = timed(lambda: predict(scored, ds, grad=False), repeats=3)
    _, g_hat = predict(scored.fitted(), grad_ds, grad=True)
    label = "DiffCo" if own else "DiffCo (w/o AL)"
    rows = [evaluate_predictions(label, ds, d_hat, g_hat, seconds, False, reach)]
    if own:
        return rows
    scores, grads, d_true, g_true, qs, adapt_time = [], [], [], [], [], 0.0
    for i in range(min(s.al_scenes, len(ds))):
        scene = ds.scene(i)
        adapted, t = timed(
            lambda scene=scene, i=i: base.adapt(scene, n_explore=s.al_explore, seed=i)
        )
        adapt_time += t
        q = scene.robot.sample(s.al_queries, seed=[7, i])
        f, gf = signed_distance_and_grad(scene, q)
        scores.append(adapted.distance(scene, q))
        grads.append(adapted.fitted().distance_and_grad(scene, q)[1])
        d_true.append(f)
        g_true.append(gf)
        qs.append(q)
    pooled = Dataset(
        env,
        np.concatenate(qs),
        np.zeros((0, 0, 2)),
        np.zeros((0, 0, 0, 2)),
        np.zeros((0, 0), np.int32),
        np.concatenate(d_true),
        np.concatenate(g_true),
        np.zeros(0, np.int64),
    )
    per_scene = adapt_time / max(min(s.al_scenes, len(ds)), 1)
    rows.append(
        evaluate_predictions(
            "DiffCo (w/ AL)",
            pooled,
            np.concatenate(scores),
            np.concatenate(grads),
            per_scene * len(ds),
            False,
            reach,
        )
    )
    return rows


def _not_trained(method: str, env: str) -> Result:
    """The row of missing weights: shown as 'not trained yet' (``score`` None)."""
    nan = float("nan")
    return Result(method, env, 0, nan, None, None, nan, None, None, 0, None, None)


def table1_env(
    env: str, s: TableSettings, weights_dir: Path = WEIGHTS_DIR, used: dict | None = None
) -> tuple[list[Result], float | None]:
    """All methods on one environment, and Welch's p of GraphDistNet (gdnplan) vs ClearanceNet
    errors. Every GraphDistNet row is listed; missing weights give a 'not trained yet' row."""
    from .models import load_model

    ds = test_set(env, s.n)
    (_, _), coal_s = timed(lambda: coal_predict(ds, grad=False))
    rows = [
        Result("coal", env, len(ds), coal_s, None, None, float("nan"), None, None, 0, None, ds.d)
    ]
    rows += diffco_rows(env, ds, s)
    learned = {}
    files = {"ClearanceNet": f"clearancenet_{env}.safetensors"}
    files |= {name: f.format(env=env) for name, f in GRAPHDISTNET_FILES.items()}
    for name, file in files.items():
        path = Path(weights_dir) / file
        if not path.exists():
            if name in PAPER_ROW:
                rows.append(_not_trained(name, env))
            continue
        if used is not None:
            used[file] = sha256_prefix(path)
        if name == "ClearanceNet":
            model = clearancenet_of_env(env, weights_dir)
        else:
            model = BatchedGraphDistNet(load_model(path), DRAWS.get(name, 1))
        learned[name] = evaluate_model(model, env, s.n, s.n_grad, ds=ds)
        rows.append(replace(learned[name], method=name))
    return rows, welch_p(rows, GDN)


def table1(
    envs: tuple[str, ...] = ENVS, fast: bool = False, log=print, weights_dir: Path = WEIGHTS_DIR
):
    """Run Table I: ({env: (rows, p)}, missing weights, {weights file: sha256 prefix at load}).

    ``fast`` uses :meth:`TableSettings.fast`.
    """
    import torch

    threads = torch.get_num_threads()
    torch.set_num_threads(1)  # stable timings on a shared CPU; every network gets one thread
    s = TableSettings.fast() if fast else TableSettings()
    out, used = {}, {}
    try:
        for env in envs:
            out[env] = table1_env(env, s, weights_dir, used)
            log(f"env {env}: " + ", ".join(r.method for r in out[env][0]))
    finally:
        torch.set_num_threads(threads)
    files = {"ClearanceNet": "clearancenet_{env}.safetensors", **GRAPHDISTNET_FILES}
    missing = [
        f"{name} {env}"
        for env in envs
        for name, file in files.items()
        if not (Path(weights_dir) / file.format(env=env)).exists()
    ]
    return out, missing, used
