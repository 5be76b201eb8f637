"""ClearanceNet (Kew, Ichter, Bandari, Lee, Faust, "Neural Collision Clearance Estimator for
Batched Motion Planning", WAFR 2020) as GraphDistNet's paper used it (Table I).

An MLP regresses the signed distance from the concatenation of the joint angles and a
fixed-size obstacle vector:

    d̂(q, O) = MLP([q / π, φ(O)]),    ∂d̂/∂q by autograd,

with φ(O) for square environments (a–d) the pose of every obstacle in generation order,
(c_x, c_y, cos 4θ, sin 4θ) per square (centre in m; θ the direction of its first edge, so a
quarter turn gives the same code, as it gives the same square), and for α-shape environments (e)
the zero-padded vertices of every obstacle (P × V × 2, m). The obstacle count and vertex count
are fixed per environment; that is ClearanceNet's limitation the paper discusses. Dropout p = 0.5
after each hidden layer for (d) and (e) as in the paper; evaluation runs without dropout.

Training (:func:`train`) minimises ((d̂ − f) / reach)² with Adam on the same ``data/<env>/train``
split as GraphDistNet (10 % held out for validation, learning rate halved after 3 epochs without
validation improvement, early stopping, wall-clock budget). It is a small loop of its own because
:mod:`gdnplan.train` builds graph tensors for GraphDistNet only.

Weights: ``<path>.safetensors`` (state dict) + ``<path>.json`` card with ``"model":
"clearancenet"`` and the config, loadable with :func:`load`.
"""

from __future__ import annotations

import json
import math
import time
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np
import torch
from torch import nn

from ..data import Dataset, pad_polygons
from ..errors import InputError
from ..scene import Scene, make_scene
from .checks import build_net, card_config, check_count, check_fits, check_layout
from .threads import check_threads, torch_threads
from .weights import card_path, read_weights, write_weights

POSE_ENVS = ("a", "b", "c", "d")
DROPOUT_ENVS = ("d", "e")


@dataclass(frozen=True)
class ClearanceNetConfig:
    """Architecture and input layout.

    Attributes:
        env: environment the obstacle vector is laid out for.
        dof: joints of the robot.
        n_obstacles: P, obstacles in the vector (fewer are zero-padded).
        n_vertices: V, vertices per obstacle for the ``"vertices"`` encoding.
        encoding: ``"pose"`` (squares) or ``"vertices"`` (α-shapes).
        hidden: widths of the hidden layers.
        dropout: dropout probability after each hidden layer (0 = none).
        scale: output scale (m): the network predicts d / scale (the robot's reach).
    """

    env: str
    dof: int
    n_obstacles: int
    n_vertices: int
    encoding: str
    hidden: tuple[int, ...] = (256, 256, 256)
    dropout: float = 0.0
    scale: float = 1.0

    @classmethod
    def for_env(cls, env: str, **changes) -> ClearanceNetConfig:
        """The paper's setting of environment ``env`` (dropout 0.5 for d and e)."""
        scene = make_scene(env, seed=0)
        enc = "pose" if env in POSE_ENVS else "vertices"
        base = cls(
            env=env,
            dof=scene.robot.dof,
            n_obstacles=len(scene.obstacles),
            n_vertices=15 if enc == "vertices" else 4,
            encoding=enc,
            dropout=0.5 if env in DROPOUT_ENVS else 0.0,
            scale=round(scene.robot.reach, 6),
        )
        return ClearanceNetConfig(**{**asdict(base), **changes})

    @classmethod
    def from_dict(cls, data: dict) -> ClearanceNetConfig:
        """The config of a card (``hidden`` a list there); InputError on bad fields."""
        config = cls(**{**data, "hidden": tuple(data.get("hidden", cls.hidden))})
        ints = (config.dof, config.n_obstacles, config.n_vertices, *config.hidden)
        if not all(isinstance(v, int) and not isinstance(v, bool) and v >= 1 for v in ints):
            raise InputError(
                "ClearanceNet config: dof, n_obstacles, n_vertices, hidden must be ≥ 1"
            )
        if config.encoding not in ("pose", "vertices") or not isinstance(config.env, str):
            raise InputError(f"ClearanceNet config: unknown encoding {config.encoding!r}")
        if not (isinstance(config.dropout, (int, float)) and 0 <= config.dropout < 1):
            raise InputError(f"ClearanceNet config: dropout in [0, 1), got {config.dropout!r}")
        if not (isinstance(config.scale, (int, float)) and 0 < config.scale < math.inf):
            raise InputError(f"ClearanceNet config: scale must be positive, got {config.scale!r}")
        return config

    @property
    def n_features(self) -> int:
        per = 4 if self.encoding == "pose" else 2 * self.n_vertices
        return self.dof + self.n_obstacles * per


def obstacle_vector(config: ClearanceNetConfig, polygons: np.ndarray, sizes: np.ndarray):
    """φ(O) (n, F_o) from padded polygons (n, P, V, 2) and vertex counts (n, P)."""
    n, p_have = sizes.shape
    if p_have > config.n_obstacles:
        raise InputError(
            f"obstacles: ClearanceNet of env {config.env} takes at most "
            f"{config.n_obstacles} obstacles, got {p_have}"
        )
    if config.encoding == "pose":
        present = sizes > 0
        count = np.maximum(sizes, 1)[..., None]
        idx = np.arange(polygons.shape[2])[None, None, :, None] < sizes[..., None, None]
        center = (polygons * idx).sum(2) / count
        edge = polygons[:, :, 1] - polygons[:, :, 0]
        theta = np.arctan2(edge[..., 1], edge[..., 0])
        feats = np.stack([center[..., 0], center[..., 1], np.cos(4 * theta), np.sin(4 * theta)], -1)
        feats = feats * present[..., None]
    else:
        if polygons.shape[2] > config.n_vertices:
            raise InputError(
                f"obstacles: at most {config.n_vertices} vertices per polygon, "
                f"got {polygons.shape[2]}"
            )
        feats = np.zeros((n, p_have, config.n_vertices, 2))
        feats[:, :, : polygons.shape[2]] = polygons
        feats = feats.reshape(n, p_have, -1)
    out = np.zeros((n, config.n_obstacles, feats.shape[-1]))
    out[:, :p_have] = feats
    return out.reshape(n, -1)


class ClearanceNet(nn.Module):
    """The MLP: (B, dof + F_o) -> (B,) distance (m)."""

    def __init__(self, config: ClearanceNetConfig):
        super().__init__()
        self.config = config
        layers: list[nn.Module] = []
        width = config.n_features
        for h in config.hidden:
            layers += [nn.Linear(width, h), nn.ReLU()]
            if config.dropout > 0:
                layers.append(nn.Dropout(config.dropout))
            width = h
        layers.append(nn.Linear(width, 1))
        self.mlp = nn.Sequential(*layers)

    def forward(self, q: torch.Tensor, obstacles: torch.Tensor) -> torch.Tensor:
        x = torch.cat([q / math.pi, obstacles], -1)
        return self.mlp(x).squeeze(-1) * self.config.scale


class ClearanceNetModel:
    """ClearanceNet as a :class:`~gdnplan.models.DistanceModel` (float64 at the API), its
    inference with ``threads`` torch threads (None: the library default, 1;
    :mod:`gdnplan.models.threads`)."""

    is_distance = True

    def __init__(
        self,
        net: ClearanceNet,
        card: dict | None = None,
        chunk: int = 8192,
        threads: int | None = None,
    ):
        self.net = net.eval()
        self.threads = check_threads(threads)
        self.card = card or {}
        self.chunk = chunk
        self.name = "ClearanceNet"
        self.dtype = next(net.parameters()).dtype  # float32 normally; float64 for checks

    def _run(self, q: np.ndarray, obst: np.ndarray, grad: bool):
        with torch_threads(self.threads):
            return self._run_chunks(q, obst, grad)

    def _run_chunks(self, q: np.ndarray, obst: np.ndarray, grad: bool):
        ds, gs = [], []
        for s in range(0, len(q), self.chunk):
            qt = torch.as_tensor(q[s : s + self.chunk], dtype=self.dtype)
            ot = torch.as_tensor(obst[s : s + self.chunk], dtype=self.dtype)
            if grad:
                qt.requires_grad_(True)
                with torch.enable_grad():
                    d = self.net(qt, ot)
                    (g,) = torch.autograd.grad(d.sum(), qt)
                gs.append(g.double().numpy())
            else:
                with torch.inference_mode():
                    d = self.net(qt, ot)
            ds.append(d.detach().double().numpy())
        return np.concatenate(ds), (np.concatenate(gs) if grad else None)

    def _scene_vector(self, scene: Scene, b: int) -> np.ndarray:
        self.check_scene(scene)
        polys, sizes = pad_polygons([list(scene.obstacles)])
        return np.repeat(obstacle_vector(self.net.config, polys, sizes), b, 0)

    def check_scene(self, scene: Scene) -> None:
        """InputError unless the weights fit ``scene``'s robot and obstacles (models/checks.py)."""
        config = self.net.config
        check_fits(self.card, scene, config.dof)
        check_layout(self.card, scene, lambda: make_scene(config.env))
        if config.encoding == "pose" and any(len(p) != 4 for p in scene.obstacles):
            raise InputError(
                f"obstacles: ClearanceNet of env {config.env} encodes squares by their pose; "
                "this scene has other polygons (use GraphDistNet or coal)"
            )

    def distance(self, scene: Scene, q: np.ndarray) -> np.ndarray:
        q = scene.robot.check_q(q)
        return self._run(q, self._scene_vector(scene, len(q)), False)[0]

    def distance_and_grad(self, scene: Scene, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        q = scene.robot.check_q(q)
        return self._run(q, self._scene_vector(scene, len(q)), True)

    def predict_dataset(self, ds: Dataset, grad: bool) -> tuple[np.ndarray, np.ndarray | None]:
        """Every sample of ``ds`` with its own obstacles, in one batched pass."""
        return self._run(ds.q, obstacle_vector(self.net.config, ds.obstacles, ds.sizes), grad)

    def save(self, path: Path | str) -> Path:
        """Write ``path`` (.safetensors) and its JSON card atomically; returns ``path``."""
        card = {**self.card, "model": "clearancenet", "config": asdict(self.net.config)}
        return write_weights(path, self.net.state_dict(), card)


def load(path: Path | str, threads: int | None = None) -> ClearanceNetModel:
    """A :class:`ClearanceNetModel` from ``path`` (.safetensors) and its JSON card, running
    inference with ``threads`` torch threads (None: the library default, 1)."""
    threads = check_threads(threads)
    path = Path(path)
    tensors, card = read_weights(path)
    if card.get("model") != "clearancenet":
        raise InputError(f"weights: {card_path(path)} is not a ClearanceNet card")
    config = card_config(path, card, "ClearanceNet", ClearanceNetConfig.from_dict)
    check_count(len(config.hidden) or 1, len(tensors), "hidden", path)
    net = build_net(path, "ClearanceNet", lambda: ClearanceNet(config), tensors)
    return ClearanceNetModel(net, card, threads=threads)


def train(
    env: str,
    train_set: Dataset,
    config: ClearanceNetConfig | None = None,
    batch: int = 256,
    lr: float = 1e-3,
    epochs: int = 200,
    patience: int = 10,
    time_budget: float | None = None,
    seed: int = 0,
) -> ClearanceNetModel:
    """Adam on ((d̂ − f)/scale)², best validation epoch kept (see the module docstring).

    Args:
        env: environment (sets the input layout unless ``config`` is given).
        train_set: training samples (10 % become the validation set).
        time_budget: stop after this many seconds of training (s).

    Returns:
        The trained model; its card records the data size, epochs, time and validation MAE.
    """
    config = config or ClearanceNetConfig.for_env(env)
    torch.manual_seed(seed)
    order = np.random.default_rng(seed).permutation(len(train_set))
    n_val = max(len(train_set) // 10, 1)
    obst = obstacle_vector(config, train_set.obstacles, train_set.sizes)
    q = torch.as_tensor(train_set.q, dtype=torch.float32)
    o = torch.as_tensor(obst, dtype=torch.float32)
    d = torch.as_tensor(train_set.d, dtype=torch.float32)
    val, tr = torch.as_tensor(order[:n_val]), torch.as_tensor(order[n_val:])
    net = ClearanceNet(config)
    opt = torch.optim.Adam(net.parameters(), lr=lr)
    best, best_state, stale, plateau, log = math.inf, None, 0, 0, []
    start = time.perf_counter()
    for epoch in range(epochs):
        if stale >= patience or (time_budget and time.perf_counter() - start > time_budget):
            break
        net.train()
        perm = tr[torch.as_tensor(np.random.default_rng([seed, epoch]).permutation(len(tr)))]
        for s in range(0, len(perm), batch):
            rows = perm[s : s + batch]
            loss = ((net(q[rows], o[rows]) - d[rows]) / config.scale).square().mean()
            opt.zero_grad()
            loss.backward()
            opt.step()
        net.eval()
        with torch.inference_mode():
            val_mae = float((net(q[val], o[val]) - d[val]).abs().mean())
        log.append({"epoch": epoch, "val_mae_m": val_mae, "lr": opt.param_groups[0]["lr"]})
        if val_mae < best:
            best, stale, plateau = val_mae, 0, 0
            best_state = {k: v.detach().clone() for k, v in net.state_dict().items()}
        else:
            stale, plateau = stale + 1, plateau + 1
            if plateau >= 3:
                plateau = 0
                for g in opt.param_groups:
                    g["lr"] /= 2
    net.load_state_dict(best_state)
    card = {
        "env": env,
        "data": {"train_dir": f"data/{env}/train", "n_train": len(tr), "n_val": n_val},
        "training": {
            "seed": seed,
            "batch": batch,
            "lr": lr,
            "epochs": len(log),
            "best_val_mae_m": best,
            "seconds": time.perf_counter() - start,
            "threads": torch.get_num_threads(),
        },
        "parameters": sum(p.numel() for p in net.parameters()),
    }
    return ClearanceNetModel(net, card)


def train_and_save(
    env: str, time_budget: float = 120.0, patience: int = 10, out: Path | str | None = None
) -> dict:
    """Train on ``data/<env>/train``, score on the test split, write ``weights/clearancenet_<env>``.

    Returns the card (training log summary and test metrics: n, MAE (m), AUC, ACD).
    """
    from ..data import load, split_dir
    from ..evaluate import evaluate_model

    torch.set_num_threads(1)
    model = train(env, load(split_dir(env, "train")), patience=patience, time_budget=time_budget)
    r = evaluate_model(model, env, n=5000)
    model.card["test"] = {"n": r.n, "mae_m": r.mae, "auc": r.auc, "acd": r.acd, "n_grad": r.n_grad}
    model.card["command"] = (
        f"python -m gdnplan.models.clearancenet {env} --time-budget {time_budget:g} "
        f"--patience {patience}"
    )
    model.save(out or Path("weights") / f"clearancenet_{env}.safetensors")
    return model.card


if __name__ == "__main__":
    import argparse

    parser = argparse.ArgumentParser(description="Train ClearanceNet baselines (Table I).")
    parser.add_argument("envs", nargs="+", choices=["a", "b", "c", "d", "e"])
    parser.add_argument("--time-budget", type=float, default=120.0, help="seconds per env")
    parser.add_argument("--patience", type=int, default=10, help="epochs without improvement")
    args = parser.parse_args()
    for env in args.envs:
        card = train_and_save(env, args.time_budget, args.patience)
        print(env, json.dumps({"training": card["training"], "test": card["test"]}))
