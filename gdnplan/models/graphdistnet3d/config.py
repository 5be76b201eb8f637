"""GraphDistNet-3D's architecture :class:`GraphDistNet3DConfig` and its dict form.

Every field is checked for its type and range when a config is made (a card, code,
``with_``): InputError naming the field (:mod:`gdnplan.models.fields` has the rules and
bounds). The ranges: ``layers`` 1 … 64; ``hidden`` and every width of ``mlp`` / ``readout``
1 … 4096, at most 16 widths each; ``cross_k`` 1 … 64; ``rim`` 3 … 64 points; ``tau`` and
``tau_min`` in [1e-12, 1e6]; ``length`` and ``scale`` in [1e-3, 1e3] m; ``origin`` three
numbers of magnitude ≤ 1e3 m; ``min_readout`` true / false only.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, fields, replace

from ...errors import InputError
from ..fields import (
    MAX_CROSS_K,
    MAX_LAYERS,
    MAX_LENGTH,
    MAX_TEMPERATURE,
    MAX_WIDTH,
    MIN_LENGTH,
    MIN_TEMPERATURE,
    check_flag,
    check_int,
    check_point,
    check_real,
    check_widths,
)

MAX_RIM = 64  # points per cylinder rim of the robot graph


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
        """Check every field's type and range (module docstring; InputError naming the field)
        and store lists as tuples, numbers of real fields as floats."""
        for name, value in _checked(self).items():
            object.__setattr__(self, name, value)

    def to_dict(self) -> dict:
        return asdict(self)

    @classmethod
    def from_dict(cls, data: dict) -> GraphDistNet3DConfig:
        known = {f.name for f in fields(cls)}
        unknown = set(data) - known
        if unknown:
            raise InputError(f"config: unknown GraphDistNet-3D options {sorted(unknown)}")
        return cls(**dict(data))

    def with_(self, **changes) -> GraphDistNet3DConfig:
        return replace(self, **changes)


def _checked(c: GraphDistNet3DConfig) -> dict:
    """The fields of ``c`` checked (bounds: :mod:`gdnplan.models.fields`)."""
    return {
        "layers": check_int(c.layers, "layers", 1, MAX_LAYERS),
        "hidden": check_int(c.hidden, "hidden", 1, MAX_WIDTH),
        "mlp": check_widths("mlp", c.mlp),
        "readout": check_widths("readout", c.readout),
        "cross_k": check_int(c.cross_k, "cross_k", 1, MAX_CROSS_K),
        "tau": check_real("tau", c.tau, MIN_TEMPERATURE, MAX_TEMPERATURE),
        "length": check_real("length", c.length, MIN_LENGTH, MAX_LENGTH, " m"),
        "scale": check_real("scale", c.scale, MIN_LENGTH, MAX_LENGTH, " m"),
        "origin": check_point("origin", c.origin, 3),
        "rim": check_int(c.rim, "rim", 3, MAX_RIM),
        "min_readout": check_flag("min_readout", c.min_readout),
        "tau_min": check_real("tau_min", c.tau_min, MIN_TEMPERATURE, MAX_TEMPERATURE),
    }
