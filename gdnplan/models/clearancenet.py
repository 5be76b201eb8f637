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

Training: :mod:`gdnplan.train_clearancenet` (``gdnplan train --model clearancenet``).

Weights: ``<path>.safetensors`` (state dict) + ``<path>.json`` card with ``"model":
"clearancenet"`` and the config, loadable with :func:`load`.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np
import torch
from torch import nn

from ..errors import InputError
from ..geometry import pad_polygons
from ..scene import Scene, check_scene, make_scene
from .checks import build_net, card_config, check_count, check_fits, check_layout
from .fields import (
    MAX_LENGTH,
    MIN_LENGTH,
    check_choice,
    check_int,
    check_real,
    check_widths,
    shown,
)
from .outputs import finite
from .settings import Checked, Fixed, check_chunk_size
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

    Every field is checked when a config is made (a card, :meth:`for_env`): counts in
    1 … :data:`LIMITS`, widths as :func:`.fields.check_widths`, ``dropout`` in [0, 0.99],
    ``scale`` in [1e-3, 1e3] m; InputError naming the field.
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

    def __post_init__(self) -> None:
        """Check every field's type and range (:data:`LIMITS`, :mod:`.fields`; InputError
        naming the field) and store ``hidden`` as a tuple, ``dropout`` and ``scale`` as floats."""
        for name, value in _checked(self).items():
            object.__setattr__(self, name, value)

    @classmethod
    def from_dict(cls, data: dict) -> ClearanceNetConfig:
        """The config of a card (``hidden`` a list there); InputError on bad fields."""
        return cls(**data)

    @property
    def n_features(self) -> int:
        per = 4 if self.encoding == "pose" else 2 * self.n_vertices
        return self.dof + self.n_obstacles * per


# Ranges of the config's counts (the widths: :mod:`.fields`, MAX_WIDTH and MAX_DEPTH).
LIMITS = {"dof": 64, "n_obstacles": 1024, "n_vertices": 1024}


def _checked(c: ClearanceNetConfig) -> dict:
    """The fields of ``c`` checked: counts in 1 … :data:`LIMITS`, ``encoding`` pose or
    vertices, ``dropout`` in [0, 0.99], ``scale`` in [1e-3, 1e3] m (float32-safe)."""
    if not isinstance(c.env, str) or not 0 < len(c.env) <= 64:
        raise InputError(f"env: expected an environment name, got {shown(c.env)}")
    counts = {k: check_int(getattr(c, k), k, 1, high) for k, high in LIMITS.items()}
    return counts | {
        "encoding": check_choice("encoding", c.encoding, ("pose", "vertices")),
        "hidden": check_widths("hidden", c.hidden),
        "dropout": check_real("dropout", c.dropout, 0.0, 0.99),
        "scale": check_real("scale", c.scale, MIN_LENGTH, MAX_LENGTH, " m"),
    }


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
    threads = Checked(check_threads)  # settable later, checked as here (models/settings.py)
    chunk = Checked(check_chunk_size)
    dtype = Fixed()  # the network's

    def __init__(
        self,
        net: ClearanceNet,
        card: dict | None = None,
        chunk: int = 8192,
        threads: int | None = None,
    ):
        self.net = net.eval()
        self.threads = threads
        self.card = card or {}
        self.chunk = chunk
        self.name = "ClearanceNet"
        self.source: str | None = None  # the weights file it was loaded from (messages)
        self.dtype = next(net.parameters()).dtype  # float32 normally; float64 for checks

    def _run(self, q: np.ndarray, obst: np.ndarray, grad: bool):
        """(d̂ (B,), ∂d̂/∂q (B, dof) or None), all finite (else InputError)."""
        with torch_threads(self.threads):
            d, g = self._run_chunks(q, obst, grad)
        finite(self, d, g)
        return d, g

    def _run_chunks(self, q: np.ndarray, obst: np.ndarray, grad: bool):
        if len(q) == 0:  # an empty batch: empty (0,) and (0, dof) arrays, as coal gives
            return np.zeros(0), (np.zeros(q.shape) if grad else None)
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
        check_scene(scene, "planar", "a 3-D model (ClearanceNet3D)")
        q = scene.robot.check_q(q)
        return self._run(q, self._scene_vector(scene, len(q)), False)[0]

    def distance_and_grad(self, scene: Scene, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        check_scene(scene, "planar", "a 3-D model (ClearanceNet3D)")
        q = scene.robot.check_q(q)
        return self._run(q, self._scene_vector(scene, len(q)), True)

    def predict_dataset(self, ds, grad: bool) -> tuple[np.ndarray, np.ndarray | None]:
        """Every sample of ``ds`` (a :class:`gdnplan.data.Dataset`) with its own obstacles, in
        one batched pass."""
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
    model = ClearanceNetModel(net, card, threads=threads)
    model.source = str(path)
    return model
