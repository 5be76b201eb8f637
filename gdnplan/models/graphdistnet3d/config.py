"""GraphDistNet-3D's architecture :class:`GraphDistNet3DConfig` and its dict form."""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, fields, replace

import numpy as np

from ...errors import InputError


@dataclass(frozen=True)
class GraphDistNet3DConfig:
    """Architecture and normalisation of GraphDistNet-3D (the planner-safe variant: soft
    k-nearest partners, one-way cross edges; LeakyReLU 0.2 as in the paper).

    Attributes:
        layers: K message-passing layers. hidden: d_h, node feature size.
        mlp: hidden widths of each h_k. readout: hidden widths of the final MLP.
        cross_k: soft partners among the k + 1 nearest obstacle nodes (the farthest at weight 0).
        tau: initial temperature τ of the partner weights (normalised units², learned per layer).
        length: metres per normalised coordinate unit, x = (p − origin) / length: the size of
            the geometry the messages resolve (link radii, clearances), so that the relative
            vectors of edges and cross edges are O(1) at initialisation.
        scale: metres per unit of the net's output (the arm's reach); d̂ = scale · net output.
        origin: (x, y, z) subtracted from coordinates before scaling (the base, m).
        rim: points per cylinder rim of the robot graph (:func:`gdnplan.graph3d.robot_graph3d`).
        min_readout: add a soft minimum over the robot nodes of a per-node distance estimate to
            the pooled readout (:class:`~.network.GraphDistNet3D`), so that the one node near
            contact decides d̂ instead of being averaged with the other N_r − 1. False: the
            paper's readout alone (weights without it load unchanged).
        tau_min: initial temperature τ_m of that soft minimum (normalised units, learned).
    """

    layers: int = 4
    hidden: int = 32
    mlp: tuple[int, ...] = (32, 32, 32)
    readout: tuple[int, ...] = (32, 32, 32)
    cross_k: int = 4
    tau: float = 2.0
    length: float = 0.1
    scale: float = 1.0
    origin: tuple[float, float, float] = (0.0, 0.0, 0.0)
    rim: int = 8
    min_readout: bool = False
    tau_min: float = 0.05

    def __post_init__(self) -> None:
        for f in fields(self):
            value = getattr(self, f.name)
            if any(isinstance(v, float) and not math.isfinite(v) for v in np.ravel(value)):
                raise InputError(f"{f.name}: expected finite numbers, got {value!r}")
        if min(self.layers, self.hidden, self.cross_k) < 1 or min(self.scale, self.tau) <= 0:
            raise InputError("layers, hidden, cross_k, tau and scale must be positive")
        if self.tau_min <= 0:
            raise InputError(f"tau_min: expected a positive temperature, got {self.tau_min}")
        if self.length <= 0:
            raise InputError(f"length: expected a positive length (m), got {self.length}")
        if len(self.origin) != 3:
            raise InputError(f"origin: expected (x, y, z), got {self.origin!r}")
        if self.rim < 3:
            raise InputError(f"rim: expected at least 3 points per rim, got {self.rim}")

    def to_dict(self) -> dict:
        return asdict(self)

    @classmethod
    def from_dict(cls, data: dict) -> GraphDistNet3DConfig:
        known = {f.name for f in fields(cls)}
        unknown = set(data) - known
        if unknown:
            raise InputError(f"config: unknown GraphDistNet-3D options {sorted(unknown)}")
        data = dict(data)
        for key in ("mlp", "readout", "origin"):
            if key in data:
                data[key] = tuple(data[key])
        return cls(**data)

    def with_(self, **changes) -> GraphDistNet3DConfig:
        return replace(self, **changes)
