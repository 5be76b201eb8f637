"""Training GraphDistNet on the datasets of :mod:`gdnplan.data`: :func:`train` with its
:class:`TrainConfig` (architecture, loss, schedule, data; :mod:`.graphdistnet_config`), through
the shared loop :func:`gdnplan.train.fit.fit`.

The loss is :mod:`.loss`'s; ∂d̂/∂q for its gradient terms comes from the node Jacobians
(:mod:`.tensors`). Model selection scores the validation split by the loss's terms,
MAE / scale + λ · ACD (λ = ``grad_weight``; the ACD only when λ > 0). Each epoch writes a
checkpoint in the run directory, so an interrupted run resumes where it stopped; fine-tuning
(``init``) lets the starting weights compete with every epoch. The weights' card records the
architecture (``config``), the loss and schedule (``training``), the data, the test metrics
and the git commit.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import torch

from ..assets import is_file
from ..data import DATA_DIR, Dataset, concat, env_robot, load, split_dir
from ..errors import InputError
from ..metrics import roc_auc, sha256_prefix, used_cosine_distances
from ..models.graphdistnet import GraphDistNet, GraphDistNetConfig
from ..models.weights import card_path, read_card
from .checkpoint import check_resume
from .fit import fit, validation_split
from .graphdistnet_config import LEGACY as LEGACY
from .graphdistnet_config import PRESETS as PRESETS
from .graphdistnet_config import TrainConfig as TrainConfig
from .graphdistnet_config import card_settings as card_settings
from .graphdistnet_config import legacy_config
from .graphdistnet_config import split_config as split_config
from .loss import GraphDistNetLoss, distance_loss, gradient_loss
from .report import evaluate, git_sha, plot_losses, save_weights
from .tensors import Tensors, forward_with_grad, predict, tensors

OUT_DIR = Path("weights")  # default output folder of trained weights (working directory)
RUNS_DIR = Path("runs")  # default run folders (checkpoints, logs), working directory


def check_env(ds: Dataset, env: str, where: Path | str) -> Dataset:
    """``ds`` when its samples are of environment ``env``; InputError naming both otherwise."""
    if ds.env != env:
        raise InputError(
            f"data: {where} holds samples of environment {ds.env!r}, not {env!r}; generate "
            f"them with `gdnplan generate --env {env}` or train with --env {ds.env}"
        )
    return ds


def init_tensors(path: Path) -> dict[str, torch.Tensor]:
    """The tensors of the ``--init`` weights ``path``: InputError unless its card (when it has
    one) is planar GraphDistNet's and its tensors are finite, within ±``MAX_WEIGHT``
    (:mod:`gdnplan.models.outputs`; 3-D weights read as unknown options, NaN or huge ones as a
    training that diverged)."""
    from ..models.checks import load_tensors
    from ..models.outputs import check_magnitudes

    path = Path(path)
    if not is_file(path, "--init"):  # a folder, a pipe (reading it would wait for ever)
        raise InputError(f"--init: {path} does not exist or is not a regular file")
    # a bare tensors file (a hand-made warm start) has no card to check; a pair's card must fit
    model = read_card(path, "--init").get("model") if card_path(path).exists() else "graphdistnet"
    if model != "graphdistnet":
        raise InputError(
            f"--init: {path} holds {model!r} weights; training fine-tunes planar GraphDistNet "
            "weights (a card of model 'graphdistnet', e.g. the shipped 'd')"
        )
    tensors = load_tensors(path, "--init")
    check_magnitudes(path, tensors)
    return tensors


def check_init_outputs(net: GraphDistNet, t: Tensors, path: Path, device: str) -> None:
    """InputError when the ``--init`` network's d̂ is not finite on the first training samples
    (finite but overflowing weights: the training would stop at once as "diverged")."""
    net.eval()
    robot, obstacles = t.batch(torch.arange(min(64, len(t))), device)
    with torch.inference_mode():
        d = net(robot, obstacles, torch.Generator(device=device).manual_seed(0))
    if not bool(torch.isfinite(d).all()):
        raise InputError(
            f"--init: the network of {path} gives NaN or infinite distances on the training "
            "data before any step (its weights overflow); start from other weights"
        )


def _load_init(net: GraphDistNet, path: Path) -> None:
    """Load the weights at ``path`` into ``net``; InputError if missing or of another shape.

    Weights without the ``node_distance`` input w_k start a ``node_distance`` network at
    w_k = 0, the function of the loaded network, which then learns to use s_i. Weights of a
    plain readout start a ``correction_band`` network with the head's m input at weight 0 (and
    τ_m at ``tau_min``): its MLP is then the loaded estimate, used in and near overlap.
    """
    state = init_tensors(path)
    if net.config.node_distance and "distance_in" not in state:
        state["distance_in"] = torch.zeros_like(net.distance_in)
    first = state.get("head.0.weight")
    if net.config.correction_band is not None and "log_tau_min" not in state and first is not None:
        state["head.0.weight"] = torch.cat([first, first.new_zeros(len(first), 1)], 1)
        state["log_tau_min"] = net.log_tau_min.detach().clone()
    try:
        net.load_state_dict(state)
    except RuntimeError as e:
        raise InputError(f"--init: {path} does not fit this architecture ({e})") from e


def validate(
    net: GraphDistNet, val_t: Tensors, loss: GraphDistNetLoss | None = None, device: str = "cpu"
) -> dict:
    """Validation MAE (m), AUC (logged, not used for selection) and the model-selection score:
    the loss's terms, MAE / scale + λ · ACD (λ = ``grad_weight``; the ACD only when λ > 0)."""
    loss = loss or GraphDistNetLoss()
    val_hat, val_g = predict(net, val_t, device=device, grad=loss.grad_weight > 0)
    val_d = val_t.d.double().numpy()
    mae = float(np.mean(np.abs(val_hat - val_d)))
    score = mae / net.config.scale
    if val_g is not None:
        cd = used_cosine_distances(val_g, val_t.grad.double().numpy())
        score += loss.grad_weight * float(np.mean(cd))
    return {"val_mae_m": mae, "val_auc": roc_auc(-val_hat, val_d <= 0), "val_score": score}


class GraphDistNetLearner:
    """GraphDistNet's part of :func:`~gdnplan.train.fit.fit`: its loss on training rows and
    its validation score (``step_net``: the network the steps run, e.g. compiled)."""

    def __init__(
        self,
        net: GraphDistNet,
        train_t: Tensors,
        val_t: Tensors,
        weights: GraphDistNetLoss,
        device: str = "cpu",
        step_net: torch.nn.Module | None = None,
    ):
        self.net, self.train_t, self.val_t = net, train_t, val_t
        self.weights, self.device = weights, device
        self.step_net = net if step_net is None else step_net  # a compiled module refuses len()

    def __len__(self) -> int:
        return len(self.train_t)

    def loss(self, rows: torch.Tensor, generator: torch.Generator) -> torch.Tensor:
        t, dev, w, scale = self.train_t, self.device, self.weights, self.net.config.scale
        robot, obstacles = t.batch(rows, dev)
        if w.grad_weight > 0:
            jac = t.jac[rows].to(dev)
            d_hat, g_hat = forward_with_grad(self.step_net, robot, obstacles, jac, True, generator)
            loss_g = gradient_loss(g_hat, t.grad[rows].to(dev), w, scale)
        else:
            d_hat = self.step_net(robot, obstacles, generator)
            loss_g = torch.zeros((), device=dev)
        return distance_loss(d_hat, t.d[rows].to(dev), w, scale) + loss_g

    def validate(self) -> dict:
        return validate(self.net, self.val_t, self.weights, self.device)


def _datasets(env: str, c: TrainConfig, data_root: Path | str):
    """(training tensors, validation tensors, extra sets) of the run (seeded split)."""
    train_dir = split_dir(env, "train", data_root)
    full = check_env(load(train_dir, c.n_train), env, train_dir)
    if len(full) < 2:
        raise InputError(f"data: {train_dir} holds {len(full)} sample; training needs ≥ 2")
    tr, val = validation_split(len(full), c.fit.seed)
    extra_sets = [check_env(load(path), env, path) for path in c.extra]
    train_t = tensors(concat([full.subset(tr), *extra_sets]))
    return train_t, tensors(full.subset(val)), extra_sets


def train(
    env: str,
    config: TrainConfig | GraphDistNetConfig | None = None,
    name: str = "smooth",
    *,
    data_root: Path | str = DATA_DIR,
    out: Path | str | None = None,
    run_dir: Path | str | None = None,
    **legacy,
) -> dict:
    """Train GraphDistNet on ``data/<env>/train``, evaluate on ``data/<env>/test``, save weights.

    Args:
        env: environment name (its splits must exist, see :func:`gdnplan.data.generate`).
        config: the run (:class:`TrainConfig`; None: its defaults). A bare
            :class:`GraphDistNetConfig` with the old keywords (``batch=``, ``lr=``, …) still
            works, deprecated.
        name: run name (``runs/<env>-<name>``).
        data_root: the folder of ``<env>/train`` and ``<env>/test``.
        out: weights path (default ``weights/<env>.safetensors``; the card goes beside it).
        run_dir: checkpoint and loss curve (default ``runs/<env>-<name>``).

    Returns:
        The card written beside the weights (config, data, training log, test metrics).
    """
    if legacy or not (config is None or isinstance(config, TrainConfig)):
        config = legacy_config(config, legacy)
    c = config or TrainConfig()
    robot = env_robot(env)
    network = c.network.with_(
        scale=round(robot.reach, 6), origin=tuple(float(v) for v in robot.chain.joint_origins[0])
    )
    run_dir = Path(run_dir or RUNS_DIR / f"{env}-{name}")
    out = Path(out or OUT_DIR / f"{env}.safetensors")
    device = c.fit.device
    torch.manual_seed(c.fit.seed)
    train_t, val_t, extra_sets = _datasets(env, c, data_root)
    net = GraphDistNet(network).to(device)
    if c.init is not None:
        _load_init(net, Path(c.init))
        check_init_outputs(net, train_t, Path(c.init), device)
    step_net = torch.compile(net, dynamic=True) if c.compile else net
    run_dir.mkdir(parents=True, exist_ok=True)  # after the checks of the data
    ckpt = run_dir / "checkpoint.safetensors"
    settings = _settings(c, network)
    if ckpt.exists():
        check_resume(read_card(ckpt, "resume"), json.loads(json.dumps(settings)), ckpt)
    learner = GraphDistNetLearner(net, train_t, val_t, c.loss, device, step_net)
    state = fit(
        learner,
        c.fit,
        checkpoint=ckpt,
        settings=settings,
        start_weights=None if c.init is None else str(c.init),
        desc=f"{env}-{name}",
        echo=print,
    )
    plot_losses(state["log"], run_dir / "loss.png", f"{env}-{name}")
    test_dir = split_dir(env, "test", data_root)
    test = evaluate(net, check_env(load(test_dir), env, test_dir), device=device)
    card = _card(env, name, robot.name, c, state, (train_t, val_t, extra_sets), test)
    card["parameters"] = sum(p.numel() for p in net.parameters())
    save_weights(net.cpu(), card, out)
    return card


def _settings(c: TrainConfig, network: GraphDistNetConfig) -> dict:
    """What a resumed run must share with its checkpoint (architecture and loss flat)."""
    return {
        "config": {**network.to_dict(), **c.loss.to_dict()},
        "batch": c.fit.batch,
        "lr": c.fit.lr,
        "seed": c.fit.seed,
        "n_train": c.n_train,
        "extra": [str(p) for p in c.extra],
    }


def _card(env: str, name: str, robot: str, c: TrainConfig, state: dict, data, test) -> dict:
    """The weights card of a finished run (the caller adds the architecture and parameters)."""
    train_t, val_t, extra_sets = data
    log = state["log"]
    card = {
        "model": "graphdistnet",
        "name": name,
        "env": env,
        "robot": robot,
        "data": {
            "train_dir": str(split_dir(env, "train", Path("data"))),
            "train_seed": 0,
            "n_train": len(train_t),
            "n_val": len(val_t),
            "extra": {str(p): len(ds) for p, ds in zip(c.extra, extra_sets, strict=True)},
            "test_seed": 1,
            "n_test": test["n"],
        },
        "training": {
            "seed": c.fit.seed,
            "batch": c.fit.batch,
            "lr": c.fit.lr,
            "loss": c.loss.to_dict(),
            "epochs": len(log),
            "best_val_score": state["best"],
            "seconds": sum(e["seconds"] for e in log),
            "clock": c.fit.budget_clock,
            "samples_per_s": float(np.mean([e["samples_per_s"] for e in log])) if log else None,
            "device": c.fit.device,
            "threads": torch.get_num_threads(),
            "compiled": c.compile,
        },
        "parameters": None,
        "test": test,
        "git_sha": git_sha(),
    }
    if c.init is not None:
        card["init"] = {"path": str(c.init), "sha256_prefix": sha256_prefix(Path(c.init))}
        card["init"].update(state.get("init_val", {}))
    return card
