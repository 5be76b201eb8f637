"""Training and evaluation of GraphDistNet on the datasets of :mod:`gdnplan.data`.

Loss per sample (distances normalised by the config's ``scale`` = reach):

    L = w · ((d̂ − f) / scale)² / w̄ + λ · (1 − cos(∂d̂/∂q, ∂f/∂q))    (λ = ``grad_weight``, 0 = paper)
        [+ ν · ((|∂d̂/∂q| − |∂f/∂q|) / scale)²    (ν = ``grad_norm_weight``, with λ > 0)]

    w = 1 + μ · exp(−|f| / s_c)      (μ = ``contact_weight``, 0 = paper; s_c = ``contact_scale``)

(w̄ the batch mean of w: near-contact samples, where the collision label is decided, count more).

with ∂d̂/∂q = Σ_n (∂d̂/∂p_n) ∂p_n/∂q (node Jacobians). Adam, a validation split (10 % of
train) scored by the loss's terms (MAE/scale + λ · ACD), learning rate halved after 3 epochs
without improvement, early stopping after ``patience`` epochs, an optional wall-clock budget;
the best-scoring state is kept (when fine-tuning, the starting weights compete too). Each epoch
writes a checkpoint (safetensors + JSON) in the run directory, so an interrupted run resumes
where it stopped; the epoch order is a function of (seed, epoch), hence runs are
deterministic on one device.

Metrics (:func:`evaluate`, paper Table I), against coal labels on a held-out split:

* MAE = mean |d̂ − f| (m), also as a fraction of the arm's reach;
* AUC of the collision classifier d̂ ≤ margin vs f ≤ margin (Mann–Whitney rank formula);
* ACD = mean (1 − cos(∂d̂/∂q, ∂f/∂q)) over samples where coal's gradient is non-zero (a zero
  model gradient counts as cos = 0), as in :mod:`gdnplan.evaluate`.
"""

from __future__ import annotations

import json
import math
import subprocess
import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import torch
from safetensors.torch import load_file
from tqdm import tqdm

from .data import DATA_DIR, Dataset, concat, env_robot, load, split_dir
from .errors import InputError
from .files import atomic_path
from .graph import GraphBatch, RobotGraph, obstacle_graph, robot_graph, variant_graphs
from .metrics import roc_auc, sha256_prefix, used_cosine_distances
from .models.graphdistnet import GraphDistNet, GraphDistNetConfig, load_graphdistnet
from .models.weights import read_card, read_weights, write_weights

SOURCE_ROOT = Path(__file__).resolve().parent.parent  # a git checkout, when not installed
OUT_DIR = Path("weights")  # default output folder of trained weights (working directory)
RUNS_DIR = Path("runs")  # default run folders (checkpoints, logs), working directory


@dataclass(frozen=True)
class Tensors:
    """A dataset as model-ready tensors (float32), built once.

    Attributes:
        q: (n, dof) float64 numpy joint angles.
        nodes: (n, N_r, 2) robot node positions.
        jac: (n, N_r, 2, dof) node Jacobians (float32).
        obstacles: obstacle graphs of all samples.
        d: (n,) coal signed distances.
        grad: (n, dof) coal ∂f/∂q.
        robot: per-sample robot graph structure (``ur5e``: the robot varies per sample),
            padded to N_r nodes; None when every sample has ``graph``'s structure.
    """

    graph: RobotGraph
    q: np.ndarray
    nodes: torch.Tensor
    jac: torch.Tensor
    obstacles: GraphBatch
    d: torch.Tensor
    grad: torch.Tensor
    robot: GraphBatch | None = None

    def __len__(self) -> int:
        return len(self.q)

    def batch(self, rows: torch.Tensor, device: str) -> tuple[GraphBatch, GraphBatch]:
        if self.robot is None:
            robot = self.graph.batch(self.nodes[rows], device=device)
        else:
            r = self.robot  # not trimmed: rows keep N_r nodes, like the Jacobians
            robot = GraphBatch(r.nodes[rows], r.prev[rows], r.next[rows], r.mask[rows]).to(device)
        return robot, self.obstacles.index(rows).to(device)


def tensors(ds: Dataset, config: GraphDistNetConfig) -> Tensors:
    """Robot nodes, Jacobians and obstacle graphs of a dataset (densified as configured).

    Samples with different robots (``ds.variants()``) get their own graph structures, padded
    to the largest (Jacobians of padded nodes are zero); ``graph`` is then the environment
    robot's graph (its reach is the metrics' unit).
    """
    graph = robot_graph(env_robot(ds.env), config.max_edge)
    if ds.gripper is None:
        nodes, jac = graph.positions_and_jacobians(ds.q)
        structure = None
    else:
        groups = [(ds.robot(int(rows[0])), rows) for rows in ds.variants().values()]
        nodes, jac, structure = variant_graphs(groups, ds.q, config.max_edge)
    return Tensors(
        graph,
        ds.q,
        torch.as_tensor(nodes, dtype=torch.float32),
        torch.as_tensor(jac, dtype=torch.float32),
        obstacle_graph(ds.obstacles, ds.sizes, config.max_edge),
        torch.as_tensor(ds.d, dtype=torch.float32),
        torch.as_tensor(ds.grad, dtype=torch.float32),
        structure,
    )


def distance_loss(d_hat: torch.Tensor, d: torch.Tensor, config: GraphDistNetConfig) -> torch.Tensor:
    """Σ w ((d̂ − f) / scale)² / Σ w over a batch (B,) of predictions d̂ and labels f (m)."""
    err = ((d_hat - d) / config.scale).square()
    if config.contact_weight == 0:
        return err.mean()
    w = 1 + config.contact_weight * torch.exp(-d.abs() / config.contact_scale)
    return (w * err).sum() / w.sum()


def gradient_loss(g_hat: torch.Tensor, g: torch.Tensor, config: GraphDistNetConfig) -> torch.Tensor:
    """λ · mean(1 − cos(ĝ, g)) + ν · mean(((|ĝ| − |g|) / scale)²) over the samples of a batch
    with a non-zero label gradient: ĝ = ∂d̂/∂q, g = ∂f/∂q (B, dof) (m/rad), λ = ``grad_weight``,
    ν = ``grad_norm_weight`` (the slope: cosine alone leaves |ĝ| free)."""
    norm = g.norm(dim=1)
    ok = (norm > 1e-9).float()
    cos = torch.nn.functional.cosine_similarity(g_hat, g, dim=1, eps=1e-9)
    per_sample = config.grad_weight * (1 - cos)
    if config.grad_norm_weight > 0:
        slope = (g_hat.norm(dim=1) - norm) / config.scale
        per_sample = per_sample + config.grad_norm_weight * slope.square()
    return (per_sample * ok).sum() / ok.sum().clamp_min(1)


def forward_with_grad(
    net: GraphDistNet,
    robot: GraphBatch,
    obstacles: GraphBatch,
    jac: torch.Tensor,
    create_graph: bool,
    generator: torch.Generator | None = None,
) -> tuple[torch.Tensor, torch.Tensor]:
    """d̂ (B,) and ∂d̂/∂q (B, dof) = Σ_n ∂d̂/∂p_n · J_n with J (B, N_r, 2, dof)."""
    x = robot.nodes.detach().requires_grad_(True)
    with torch.enable_grad():
        d = net(robot.with_nodes(x), obstacles, generator)
        (dx,) = torch.autograd.grad(d.sum(), x, create_graph=create_graph)
    return d, torch.einsum("bni,bnij->bj", dx, jac)


def predict(
    net: GraphDistNet, t: Tensors, chunk: int = 256, device: str = "cpu", grad: bool = True
) -> tuple[np.ndarray, np.ndarray | None]:
    """d̂ (n,) and, with ``grad``, ∂d̂/∂q (n, dof) for every sample of ``t`` (float64)."""
    net.eval()
    gen = torch.Generator(device=device).manual_seed(0)
    ds, gs = [], []
    for s in range(0, len(t), chunk):
        rows = torch.arange(s, min(s + chunk, len(t)))
        robot, obstacles = t.batch(rows, device)
        if grad:
            d, g = forward_with_grad(net, robot, obstacles, t.jac[rows].to(device), False, gen)
            gs.append(g.detach().double().cpu().numpy())
        else:
            with torch.inference_mode():
                d = net(robot, obstacles, gen)
        ds.append(d.detach().double().cpu().numpy())
    return np.concatenate(ds), (np.concatenate(gs) if grad else None)


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
    t = tensors(ds, net.config)
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


def validate(net: GraphDistNet, val_t: Tensors, device: str = "cpu") -> dict:
    """Validation MAE (m), AUC (logged, not used for selection) and the model-selection score:
    the loss's terms, MAE / scale + λ · ACD (λ = ``grad_weight``; the ACD only when λ > 0)."""
    config = net.config
    val_hat, val_g = predict(net, val_t, device=device, grad=config.grad_weight > 0)
    val_d = val_t.d.double().numpy()
    mae = float(np.mean(np.abs(val_hat - val_d)))
    score = mae / config.scale
    if val_g is not None:
        cd = used_cosine_distances(val_g, val_t.grad.double().numpy())
        score += config.grad_weight * float(np.mean(cd))
    return {"val_mae_m": mae, "val_auc": roc_auc(-val_hat, val_d <= 0), "val_score": score}


def _save_checkpoint(path: Path, net: GraphDistNet, opt: torch.optim.Adam, state: dict) -> None:
    tensors = {f"net.{k}": v for k, v in net.state_dict().items()}
    for i, s in enumerate(opt.state.values()):
        for k, v in s.items():
            tensors[f"opt.{i}.{k}"] = torch.as_tensor(v)
    best = state.pop("best_state", None)
    if best is not None:
        tensors.update({f"best.{k}": v for k, v in best.items()})
    write_weights(path, tensors, state, "checkpoint")
    if best is not None:
        state["best_state"] = best


def _load_checkpoint(path: Path, net: GraphDistNet, opt: torch.optim.Adam) -> dict:
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


def _load_init(net: GraphDistNet, path: Path) -> None:
    """Load the weights at ``path`` into ``net``; InputError if missing or of another shape.

    Weights without the ``node_distance`` input w_k start a ``node_distance`` network at
    w_k = 0, the function of the loaded network, which then learns to use s_i. Weights of a
    plain readout start a ``correction_band`` network with the head's m input at weight 0 (and
    τ_m at ``tau_min``): its MLP is then the loaded estimate, used in and near overlap.
    """
    if not path.exists():
        raise InputError(f"--init: {path} does not exist")
    state = load_file(str(path))
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


def save_weights(net: GraphDistNet, card: dict, path: Path | str) -> Path:
    """Write ``path`` (safetensors) and the JSON card beside it (config included)."""
    return write_weights(path, net.state_dict(), {**card, "config": net.config.to_dict()})


load_weights = load_graphdistnet  # weights/<env>.safetensors -> GraphDistNetModel


def check_options(
    n_train: int | None,
    batch: int,
    lr: float,
    epochs: int,
    patience: int,
    time_budget: float | None,
    device: str,
) -> None:
    """InputError naming the option unless the training options of :func:`train` are usable."""
    for name, value, least in (("n_train", n_train, 2), ("batch", batch, 1), ("epochs", epochs, 1),
                               ("patience", patience, 1)):  # fmt: skip
        if value is not None and (not isinstance(value, int) or value < least):
            raise InputError(f"{name}: expected an integer ≥ {least}, got {value!r}")
    if not (isinstance(lr, (int, float)) and math.isfinite(lr) and lr >= 0):
        raise InputError(f"lr: expected a finite learning rate ≥ 0, got {lr!r}")
    if time_budget is not None and not (
        isinstance(time_budget, (int, float)) and math.isfinite(time_budget) and time_budget > 0
    ):
        raise InputError(
            f"time_budget: expected a finite number of seconds > 0, got {time_budget!r}"
        )
    try:
        dev = torch.device(device)
    except (RuntimeError, TypeError) as e:
        raise InputError(f"device: expected cpu or cuda, got {device!r}") from e
    if dev.type not in ("cpu", "cuda"):
        raise InputError(f"device: expected cpu or cuda, got {device!r}")
    if dev.type == "cuda" and (dev.index or 0) >= torch.cuda.device_count():
        raise InputError(f"device: {device} is not available on this machine; use cpu")


def check_env(ds: Dataset, env: str, where: Path | str) -> Dataset:
    """``ds`` when its samples are of environment ``env``; InputError naming both otherwise."""
    if ds.env != env:
        raise InputError(
            f"data: {where} holds samples of environment {ds.env!r}, not {env!r}; generate "
            f"them with `gdnplan generate --env {env}` or train with --env {ds.env}"
        )
    return ds


RESUME_KEYS = ("config", "batch", "lr", "seed", "n_train", "extra")


def check_resume(state: dict, settings: dict, ckpt: Path) -> None:
    """InputError naming the settings that differ from those the checkpoint's run started with
    (checkpoints written before settings were recorded are not checked)."""
    before = state.get("settings")
    if not isinstance(before, dict):
        return
    differ = sorted(k for k in settings if k in before and before[k] != settings[k])
    if "config" in differ:
        old, new = before["config"], settings["config"]
        keys = sorted(k for k in new.keys() | old.keys() if old.get(k) != new.get(k))
        differ = [k for k in differ if k != "config"] + [f"--set {k}" for k in keys]
    if differ:
        raise InputError(
            f"resume: {ckpt} was started with other settings ({', '.join(differ)}); rerun with "
            f"the same options, another --name / --run-dir, or delete the checkpoint to start over"
        )


def train(
    env: str,
    config: GraphDistNetConfig | None = None,
    name: str = "smooth",
    n_train: int | None = None,
    batch: int = 256,
    lr: float = 1e-3,
    epochs: int = 200,
    patience: int = 10,
    time_budget: float | None = None,
    seed: int = 0,
    device: str = "cpu",
    data_root: Path | str = DATA_DIR,
    out: Path | str | None = None,
    run_dir: Path | str | None = None,
    compile: bool = False,
    init: Path | str | None = None,
    extra: Sequence[Path | str] = (),
) -> dict:
    """Train GraphDistNet on ``data/<env>/train``, evaluate on ``data/<env>/test``, save weights.

    Args:
        env: environment name (its splits must exist, see :func:`gdnplan.data.generate`).
        config: architecture (``scale`` and ``origin`` are set from the robot).
        name: run name (``runs/<env>-<name>``).
        n_train: use only the first n training samples (incl. the 10 % validation part).
        time_budget: stop after this many seconds of training (s).
        device: ``"cpu"`` or ``"cuda"``.
        out: weights path (default ``weights/<env>.safetensors``; the card goes beside it).
        compile: ``torch.compile`` the training step (≈ 3× faster on CPU after a few minutes
            of compilation); validation and evaluation stay eager.
        init: fine-tune: start from these weights (same architecture as ``config``) instead
            of a random initialisation; ignored when the run resumes from its checkpoint.
        extra: more training splits (directories of shards, e.g. near-boundary samples from
            ``gdnplan generate --near``), added to the training part only: validation stays
            the 10 % of ``data/<env>/train``, the distribution of the test split.

    Returns:
        The card written beside the weights (config, data, training log, test metrics).
    """
    check_options(n_train, batch, lr, epochs, patience, time_budget, device)
    if compile and config is not None and config.grad_weight > 0:
        raise InputError(
            "compile: the gradient loss (grad_weight > 0) differentiates ∂d̂/∂q, a double "
            "backward that torch.compile does not support; train it without --compile"
        )
    robot = env_robot(env)
    config = (config or GraphDistNetConfig.smooth()).with_(
        scale=round(robot.reach, 6), origin=tuple(float(v) for v in robot.chain.joint_origins[0])
    )
    run_dir = Path(run_dir or RUNS_DIR / f"{env}-{name}")
    out = Path(out or OUT_DIR / f"{env}.safetensors")
    torch.manual_seed(seed)
    train_dir = split_dir(env, "train", data_root)
    full = check_env(load(train_dir, n_train), env, train_dir)
    if len(full) < 2:
        raise InputError(f"data: {train_dir} holds {len(full)} sample; training needs ≥ 2")
    order = np.random.default_rng(seed).permutation(len(full))
    n_val = max(len(full) // 10, 1)
    extra_sets = [check_env(load(path), env, path) for path in extra]
    train_t = tensors(concat([full.subset(order[n_val:]), *extra_sets]), config)
    val_t = tensors(full.subset(order[:n_val]), config)
    net = GraphDistNet(config).to(device)
    if init is not None:
        _load_init(net, Path(init))
    step_net = torch.compile(net, dynamic=True) if compile else net
    opt = torch.optim.Adam(net.parameters(), lr=lr)
    run_dir.mkdir(parents=True, exist_ok=True)  # after the checks of the data
    ckpt = run_dir / "checkpoint.safetensors"
    state = {"epoch": 0, "lr": lr, "best": math.inf, "stale": 0, "plateau": 0, "log": []}
    state["best_state"] = None
    state["settings"] = {"config": config.to_dict(), "batch": batch, "lr": lr, "seed": seed}
    state["settings"] |= {"n_train": n_train, "extra": [str(p) for p in extra]}
    if ckpt.exists():
        check_resume(read_card(ckpt, "resume"), json.loads(json.dumps(state["settings"])), ckpt)
        try:
            state = _load_checkpoint(ckpt, net, opt)
        except RuntimeError as e:  # a checkpoint of another architecture, without settings
            raise InputError(
                f"resume: {ckpt} does not fit this network ({' '.join(str(e).split())[:200]}); "
                "rerun with the run's options, or delete the checkpoint to start over"
            ) from e
        print(f"resumed {run_dir} at epoch {state['epoch']}")
    elif init is not None:  # the starting weights compete: fine-tuning never makes them worse
        state["init_val"] = validate(net, val_t, device)
        state["best"] = state["init_val"]["val_score"]
        state["best_state"] = {k: v.detach().clone() for k, v in net.state_dict().items()}
        print(json.dumps({"init": str(init), **state["init_val"]}))
    trained = sum(e["seconds"] for e in state["log"])
    n = len(train_t)
    while state["epoch"] < epochs and state["stale"] < patience:
        if time_budget is not None and trained >= time_budget:
            break
        epoch = state["epoch"]
        net.train()
        perm = torch.as_tensor(np.random.default_rng([seed, epoch]).permutation(n))
        gen = torch.Generator(device=device).manual_seed(seed * 100_003 + epoch)
        start = time.perf_counter()
        total = 0.0
        bar = tqdm(
            range(0, n, batch), desc=f"{env}-{name} epoch {epoch}", leave=False, mininterval=5
        )
        for s in bar:
            rows = perm[s : s + batch]
            robot_b, obst_b = train_t.batch(rows, device)
            d = train_t.d[rows].to(device)
            if config.grad_weight > 0:
                jac = train_t.jac[rows].to(device)
                d_hat, g_hat = forward_with_grad(step_net, robot_b, obst_b, jac, True, gen)
                loss_g = gradient_loss(g_hat, train_t.grad[rows].to(device), config)
            else:
                d_hat, loss_g = step_net(robot_b, obst_b, gen), torch.zeros((), device=device)
            loss = distance_loss(d_hat, d, config) + loss_g
            opt.zero_grad()
            loss.backward()
            opt.step()
            total += float(loss.detach()) * len(rows)
            bar.set_postfix(loss=f"{float(loss.detach()):.2e}", refresh=False)
        seconds = time.perf_counter() - start
        trained += seconds
        val = validate(net, val_t, device)
        score = val["val_score"]
        entry = {"epoch": epoch, "train_loss": total / n, **val, "lr": state["lr"]}
        entry.update(seconds=seconds, samples_per_s=n / seconds)
        state["log"].append(entry)
        print(json.dumps(entry))
        if score < state["best"]:
            state.update(best=score, stale=0, plateau=0)
            state["best_state"] = {k: v.detach().clone() for k, v in net.state_dict().items()}
        else:
            state["stale"] += 1
            state["plateau"] += 1
            if state["plateau"] >= 3:
                state["lr"] /= 2
                state["plateau"] = 0
                for g in opt.param_groups:
                    g["lr"] = state["lr"]
        state["epoch"] = epoch + 1
        _save_checkpoint(ckpt, net, opt, state)
    if state["best_state"] is not None:  # None: no epoch ran and no starting weights
        net.load_state_dict(state["best_state"])
    plot_losses(state["log"], run_dir / "loss.png", f"{env}-{name}")
    test_dir = split_dir(env, "test", data_root)
    test = evaluate(net, check_env(load(test_dir), env, test_dir), device=device)
    log = state["log"]
    card = {
        "model": "graphdistnet",
        "name": name,
        "env": env,
        "robot": robot.name,
        "data": {
            "train_dir": str(split_dir(env, "train", Path("data"))),
            "train_seed": 0,
            "n_train": n,
            "n_val": len(val_t),
            "extra": {str(path): len(ds) for path, ds in zip(extra, extra_sets, strict=True)},
            "test_seed": 1,
            "n_test": test["n"],
        },
        "training": {
            "seed": seed,
            "batch": batch,
            "lr": lr,
            "epochs": len(log),
            "best_val_score": state["best"],
            "seconds": sum(e["seconds"] for e in log),
            "samples_per_s": float(np.mean([e["samples_per_s"] for e in log])) if log else None,
            "device": device,
            "threads": torch.get_num_threads(),
            "compiled": compile,
        },
        "parameters": sum(p.numel() for p in net.parameters()),
        "test": test,
        "git_sha": git_sha(),
    }
    if init is not None:
        card["init"] = {"path": str(init), "sha256_prefix": sha256_prefix(Path(init))}
        card["init"].update(state.get("init_val", {}))
    save_weights(net.cpu(), card, out)
    return card


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


PRESETS = {"faithful": GraphDistNetConfig.faithful, "smooth": GraphDistNetConfig.smooth}
