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
    welch_p_value,
)
from .metrics import cosine_distances as cosine_distances
from .metrics import mean_absolute_error as mean_absolute_error
from .metrics import roc_auc as roc_auc
from .metrics import roc_curve as roc_curve
from .metrics import scene_groups as scene_groups
from .metrics import used_cosine_distances as used_cosine_distances
from .paper_figures import detour_path as detour_path  # moved; re-exported
from .paper_figures import fig5 as fig5
from .paper_figures import table1_figures as table1_figures

log = logging.getLogger(__name__)

# -------------------------------------------------------------------- Table I
ENVS = ("a", "b", "c", "d", "e")
DIFFCO_SOURCE = {"b": "a", "d": "c"}  # random env -> fixed env DiffCo is trained on (paper)

# Paper Table I: (time s, MAE, AUC, ACD); None where the paper has "-" or N/A.
PAPER: dict[str, dict[str, tuple]] = {
    "a": {
        "coal": (1.0653, None, None, None),
        "DiffCo": (0.0048, None, 1.0000, 0.3575),
        "ClearanceNet": (0.0009, 0.0082, 1.0000, 0.0255),
        "GraphDistNet": (0.0115, 0.0031, 1.0000, 0.0054),
    },
    "b": {
        "coal": (1.1822, None, None, None),
        "DiffCo (w/o AL)": (0.0054, None, 0.5031, 1.0270),
        "DiffCo (w/ AL)": (2058.2, None, 0.9948, 0.4221),
        "ClearanceNet": (0.0009, 0.1732, 0.9986, 0.2853),
        "GraphDistNet": (0.0115, 0.0390, 0.9999, 0.1748),
    },
    "c": {
        "coal": (3.1573, None, None, None),
        "DiffCo": (0.0740, None, 0.9843, 0.3202),
        "ClearanceNet": (0.0012, 0.2360, 0.9111, 0.5933),
        "GraphDistNet": (0.0574, 0.0253, 0.9990, 0.1458),
    },
    "d": {
        "coal": (4.4467, None, None, None),
        "DiffCo (w/o AL)": (0.0742, None, 0.5239, 0.9450),
        "DiffCo (w/ AL)": (75129.5, None, 0.9798, 0.3968),
        "ClearanceNet": (0.0012, 0.7725, 0.5691, 0.9491),
        "GraphDistNet": (0.0546, 0.1614, 0.9842, 0.4152),
    },
    "e": {
        "coal": (6.8432, None, None, None),
        "DiffCo (w/o AL)": (0.0350, None, 0.5200, 0.9612),
        "DiffCo (w/ AL)": (None, None, None, None),  # out of memory in the paper
        "ClearanceNet": (0.0011, 0.7479, 0.8882, 0.9767),
        "GraphDistNet": (0.1251, 0.2446, 0.9925, 0.8421),
    },
}
PAPER_P = {"a": 6e-20, "b": 2e-12, "c": 6e-60, "d": 1e-10, "e": 3e-2}


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
    trained on a (b), c (d) or one e scene (e) as is ("w/o AL") and, on the scenes of the first
    ``al_scenes`` test samples, after active learning ("w/ AL"); the latter's AUC and ACD pool
    ``al_queries`` uniform configurations per adapted scene, and its time is the mean
    adaptation time per scene × n (the paper adapts to each test scene).
    """
    from .models.diffco import DiffCo
    from .scene import make_scene

    source = make_scene(DIFFCO_SOURCE.get(env, env), seed=0)
    n_train = s.diffco_train[0 if source.robot.dof == 2 else 1]
    base = DiffCo.train(source, n=n_train, seed=0)
    reach = source.robot.reach
    grad_ds = ds.subset(slice(0, s.n_grad))
    (d_hat, _), seconds = timed(lambda: predict(base, ds, grad=False), repeats=3)
    _, g_hat = predict(base.fitted(), grad_ds, grad=True)
    label = "DiffCo" if env in ("a", "c") else "DiffCo (w/o AL)"
    rows = [evaluate_predictions(label, ds, d_hat, g_hat, seconds, False, reach)]
    if env in ("a", "c"):
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


GDN = "GraphDistNet (gdnplan)"  # the shipped weights/<env>
FAITHFUL = "GraphDistNet (paper architecture, this implementation)"  # weights/<env>_faithful
FAITHFUL_DRAWS = 8  # first-layer draws averaged in the row below
FAITHFUL_MEAN = f"GraphDistNet (paper architecture, mean of {FAITHFUL_DRAWS} first-layer draws)"
PAPER_ROW = {GDN: "GraphDistNet", FAITHFUL: "GraphDistNet", FAITHFUL_MEAN: "GraphDistNet"}
GRAPHDISTNET_FILES = {
    GDN: "{env}.safetensors",
    FAITHFUL: "{env}_faithful.safetensors",
    FAITHFUL_MEAN: "{env}_faithful.safetensors",
}
DRAWS = {FAITHFUL_MEAN: FAITHFUL_DRAWS}  # rows whose d̂ is a mean over first-layer draws


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
    return rows, _welch(rows, GDN)


def _welch(rows: list[Result], method: str) -> float | None:
    """Welch's p of ``method``'s absolute errors vs ClearanceNet's (None without both)."""
    errors = {r.method: r.abs_error for r in rows if r.abs_error is not None}
    if method not in errors or "ClearanceNet" not in errors:
        return None
    return welch_p_value(errors[method], errors["ClearanceNet"])


def network_line(card: dict) -> str:
    """One line saying what a GraphDistNet card's network and training are."""
    from .train import split_config

    flat = {**card.get("config", {}), **card.get("training", {}).get("loss", {})}
    net, loss = split_config(flat)
    parts = [
        "soft nearest-node partners" if net.cross == "soft_knn" else
        "random (one per graph), then argmax partners",
        "two-way cross edges" if net.two_way else "one-way cross edges",
    ]  # fmt: skip
    default = type(net)()
    if (net.layers, net.hidden) != (default.layers, default.hidden):  # lines stay short otherwise
        parts.append(f"{net.layers} layers of {net.hidden} features")
    if net.node_distance:
        parts.append("node distances")
    if net.min_readout:
        parts.append("soft-minimum readout")
    if net.probe_split > 1:
        parts.append(f"probe points ({net.probe_split - 1} per edge)")
    if net.correction_band is not None:
        parts.append(f"band readout ({100 * net.correction_band:g} cm)")
    terms = ["distance"]
    if loss.contact_weight:
        terms.append(f"contact weight μ = {loss.contact_weight:g}")
    if loss.grad_weight:
        terms.append(f"gradient λ = {loss.grad_weight:g}")
    if loss.grad_norm_weight:
        terms.append(f"slope ν = {loss.grad_norm_weight:g}")
    data, training = card.get("data", {}), card.get("training", {})
    near = sum((data.get("extra") or {}).values())
    samples = f"{data.get('n_train', 0):,}".replace(",", " ") + " training samples"
    samples += f" ({near:,} near contact)".replace(",", " ") if near else ""
    seconds = f"{training.get('seconds', 0):.0f} s of training"
    if card.get("init"):
        seconds = f"fine-tuned in steps (card lineage), the last {seconds}"
    return f"{', '.join(parts)}; loss: {' + '.join(terms)}; {samples}; {seconds}"


NOTES = """
Notes (how each number is made; `paper` columns are the paper's Table I):

- Samples: the first n of `data/<env>/test` (seed 1, one obstacle set per sample in b, d, e),
  or without it the same samples labelled here (`gdnplan.data.split_samples`); the same
  samples for every method. MAE, AUC and time over n; ACD over the first n_grad
  ([n] in the ACD column, all n by default; the paper sampled 100 gradients), ± its standard
  error s/√n, coal's exact gradient as reference, rows with a zero coal gradient left out.
  AUC: positives are coal's f ≤ 0, the score is −d̂.
- Time: fastest of 3 wall times of the distance batch on this shared 2-core CPU (coal: one run,
  one call per obstacle set including building its coal shapes; learned models: one batched
  pass on one torch thread, GraphDistNet including graph construction). Other jobs shared the
  CPU, so times vary between runs by up to ~10×. The paper timed a GPU for the networks.
- MAE [/reach]: metres, and as a fraction of the arm's reach (1.2 m planar2, 2.1 m planar7).
  p (GraphDistNet row): two-sided Welch's t-test between GraphDistNet's and ClearanceNet's
  absolute errors, with the method whose MAE is lower.
- DiffCo: FK-kernel perceptron (Fastron updates) trained on 3000 (2-DoF) or 5000 (7-DoF)
  coal-labelled configurations of a (for a, b), c (for c, d) or one random e scene (for e).
  AUC and time use the perceptron score; ACD uses the fitted surrogate (kernel ridge regression
  of coal's f over the labelled configurations), DiffCo's smooth score for optimisation.
  w/ AL: active learning on the scenes of the first 10 test samples (relabel support points,
  2 Gaussian perturbations each, 2000 uniform samples, continue the perceptron); AUC and ACD
  pool 200 uniform configurations per adapted scene; time = mean adaptation time per scene
  × n (extrapolated, as the paper adapts to every test scene). The paper's DiffCo w/ AL ran out
  of memory in e, hence no paper numbers there.
- GraphDistNet (gdnplan): the shipped `weights/<env>`, the planner's network (soft
  nearest-node partners and, per environment, the changes beyond the paper listed below).
  GraphDistNet (paper architecture, this implementation): `weights/<env>_faithful`, §IV as
  written (a random, then the argmax partner per graph, two-way cross edges, no node
  distances, the squared distance loss), trained on the same data for the same seconds as the
  gdnplan row (`gdnplan reproduce faithful --env <env>`), d̂ of one draw of its random
  first-layer partners (generator seed 0). GraphDistNet (paper architecture, mean of 8
  first-layer draws): the same weights, d̂ and its gradient averaged over the draws of seeds
  0–7 (8× the time). The paper does not say how its test-time d̂ treats that draw ("Although
  we randomly select each $j_c$ for initial graph construction, $j_c$ is not necessarily a
  random index after the first message passing", §IV-A). Every GraphDistNet row stands beside
  the paper's GraphDistNet numbers; where the paper-architecture rows fall short of them, and
  why: `benchmarks/results/faithful_shortfall.md` (`benchmarks/faithful_shortfall.py`) and
  docs/decisions.md.
- ClearanceNet: MLP 3×256 ReLU on [q/π, obstacle poses (centre, cos 4θ, sin 4θ) or padded
  α-shape vertices], dropout 0.5 for d and e, Adam on data/<env>/train (weights card: data,
  epochs, seconds); a 120 s training budget per environment on this CPU.
"""


def _num(v: float | None, fmt: str) -> str:
    return "–" if v is None or (isinstance(v, float) and np.isnan(v)) else format(v, fmt)


def _p_text(method: str, rows: list[Result]) -> str:
    """Welch's p of ``method`` vs ClearanceNet with the side whose MAE is lower (the test
    itself is two-sided)."""
    p = _welch(rows, method)
    if p is None:
        return "–"
    mae = {r.method: r.mae for r in rows}
    lower = "GDN" if mae[method] < mae["ClearanceNet"] else "CN"
    return f"{'< 1e-300' if p == 0 else format(p, '.1e')} ({lower} lower)"


def table1_markdown(
    results: dict[str, tuple[list[Result], float | None]], weights_dir: Path = WEIGHTS_DIR
) -> str:
    """Markdown of Table I: ours beside the paper's numbers (paper in the ``paper`` columns);
    the notes name each GraphDistNet row's network (its card in ``weights_dir``)."""
    head = (
        "| env | method | time (s) | paper | MAE (m) [/reach] | paper | p (GDN vs CN) | paper "
        "| AUC | paper | ACD [n] | paper |"
    )
    lines = [head, "|" + "---|" * 12]
    for env, (rows, _) in results.items():
        for r in rows:
            pt, pm, pa, pc = PAPER[env].get(PAPER_ROW.get(r.method, r.method), (None,) * 4)
            learned = r.method in PAPER_ROW
            if r.score is None and learned:
                lines.append(f"| {env} | {r.method} | not trained yet | {_num(pt, '.5g')} | "
                             f"| {_num(pm, '.4f')} | | {_num(PAPER_P[env], '.0e')} | "
                             f"| {_num(pa, '.4f')} | | {_num(pc, '.4f')} |")  # fmt: skip
                continue
            p_text = _p_text(r.method, rows) if learned else ""
            mae = (
                "N/A"
                if r.method.startswith("DiffCo")
                else ("–" if r.mae is None else f"{r.mae:.4f} [{r.mae_reach:.4f}]")
            )
            lines.append(
                f"| {env} | {r.method} | {r.seconds:.4g} | {_num(pt, '.5g')} | {mae} "
                f"| {_num(pm, '.4f')} | {p_text} "
                f"| {_num(PAPER_P[env], '.0e') if learned else ''} "
                f"| {_num(r.auc, '.4f')} | {_num(pa, '.4f')} "
                f"| {_num(r.acd, '.4f')}{_se_text(r)} "
                f"| {_num(pc, '.4f')} |"
            )
    return "\n".join(lines) + "\n" + NOTES + networks_notes(tuple(results), weights_dir)


def networks_notes(envs: tuple[str, ...], weights_dir: Path = WEIGHTS_DIR) -> str:
    """One line per GraphDistNet row: its network, loss and data, read from its card."""
    from .models.weights import read_card

    lines = ["", "GraphDistNet rows, from their weights' cards:", ""]
    for env in envs:
        for name, file in GRAPHDISTNET_FILES.items():
            path = Path(weights_dir) / file.format(env=env)
            what = network_line(read_card(path, "weights")) if path.exists() else (
                "not trained yet (`gdnplan reproduce faithful --env " + env + "`)")  # fmt: skip
            if name in DRAWS and path.exists():
                what += f"; d̂ and its gradient: the mean over {DRAWS[name]} first-layer draws"
            lines.append(f"- ({env}) {name}: {what}")
    return "\n".join(lines) + "\n"


def _se_text(r: Result) -> str:
    """' ± SE [n]' after an ACD, '' for rows without one."""
    return "" if r.acd is None else f" ± {r.acd_se:.4f} [{r.n_grad}]"


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
