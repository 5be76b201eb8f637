"""GraphDistNet's architecture: :class:`GraphDistNetConfig`, its presets and its dict form.

The loss and schedule of its training are training settings (:mod:`gdnplan.train`:
``GraphDistNetLoss``, ``FitConfig``). Cards written before that split hold the loss weights in
their flat ``config``; :meth:`GraphDistNetConfig.from_dict` skips them (``LOSS_KEYS``), and
``gdnplan.train.split_config`` reads them as the loss. Options that were removed
(``REMOVED``) load at their former default value and are refused at any other.

Every field is checked for its type and range when a config is made (from a card, a preset
or ``with_``): InputError naming the field (:mod:`gdnplan.models.fields` has the rules and
bounds). The ranges: ``layers`` 1 … 64; ``hidden`` and every width of ``mlp`` / ``readout``
1 … 4096, at most 16 widths each; ``cross_k`` 1 … 64; ``probe_split`` 1 … 32; ``tau`` and
``tau_min`` in [1e-12, 1e6]; ``scale`` and ``correction_band`` in [1e-3, 1e3] m; ``origin``
two numbers of magnitude ≤ 1e3 m; flags true / false only.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, fields, replace

from ...errors import InputError
from ..fields import (
    MAX_CROSS_K,
    MAX_LAYERS,
    MAX_LENGTH,
    MAX_PROBE_SPLIT,
    MAX_TEMPERATURE,
    MAX_WIDTH,
    MIN_LENGTH,
    MIN_TEMPERATURE,
    check_choice,
    check_flag,
    check_int,
    check_point,
    check_real,
    check_widths,
)


@dataclass(frozen=True)
class GraphDistNetConfig:
    """Architecture and normalisation of GraphDistNet (activation: LeakyReLU, slope 0.2, the
    paper's; graph edges are the polygons' own, not densified).

    Attributes:
        layers: K message-passing layers.
        hidden: d_h, node feature size.
        mlp: hidden widths of each h_k.
        readout: hidden widths of the final MLP.
        cross: ``"argmax"`` (the paper: at the first layer one random node j_c per graph,
            the partner of every node of the other graph, §IV-A "a single connection node per
            graph (j_{c,r}, j_{c,o})"; then the argmax partner) or ``"soft_knn"``.
        cross_k: candidates k of ``soft_knn`` (k + 1 nearest nodes are looked at).
        two_way: cross edges into both graphs (the paper). False: only robot nodes take a
            cross partner (obstacle nodes have z̄_i = z_i), so the obstacle features depend on
            the scene alone and inference computes them once per scene (package docstring).
        tau: initial temperature τ of ``soft_knn`` (normalised units², learned per layer).
        node_distance: distance-aware nodes (beyond the paper): every layer's h_k also takes
            s_i, node i's signed distance to the other graph's polygons (normalised units,
            negative inside), as an absolute input (package docstring).
        min_readout: a residual readout on the soft minimum of the node distances,
            m = −τ_m log Σ_i exp(−s_i / τ_m) (τ_m learned, initially ``tau_min``):
            d̂ = scale · (m + MLP(y_r ‖ y_o ‖ m)), the MLP's last layer starting at zero.
            Needs ``node_distance``. Between apart polygons min_i s_i is the distance itself,
            so the MLP learns a correction (penetration, edges crossing without a vertex inside).
        tau_min: initial τ_m (normalised units).
        probe_split: m's minimum also runs over the points splitting every ring edge into
            this many pieces (1: the nodes only). Needs ``min_readout``.
        correction_band: β (m) of a banded ``min_readout``, d̂ = scale · (g · MLP(…) +
            (1 − g) · m), g = σ(8 (1 − scale · m / β)): the MLP's estimate in overlap and
            near contact, m beyond ≈ 2β (None: the residual m + MLP everywhere). Needs
            ``min_readout``.
        scale: metres per normalised unit (the robot's reach); d̂ = scale · net output
            (1e-3 … 1e3 m: coordinates stay float32-safe).
        origin: (x, y) subtracted from coordinates before scaling (joint 1, m; each
            coordinate of magnitude ≤ 1e3 m).
    """

    layers: int = 4
    hidden: int = 32
    mlp: tuple[int, ...] = (32, 32, 32)
    readout: tuple[int, ...] = (32, 32, 32)
    cross: str = "soft_knn"
    cross_k: int = 4
    two_way: bool = True
    tau: float = 0.02
    node_distance: bool = False
    min_readout: bool = False
    tau_min: float = 1e-3
    probe_split: int = 1
    correction_band: float | None = None
    scale: float = 1.0
    origin: tuple[float, float] = (0.0, 0.0)

    def __post_init__(self) -> None:
        """Check every field's type and range (:mod:`gdnplan.models.fields`; InputError naming
        the field) and store lists as tuples, numbers of real fields as floats."""
        for name, value in _checked(self).items():
            object.__setattr__(self, name, value)
        if self.min_readout and not self.node_distance:
            raise InputError("min_readout needs node_distance=True (it reads the node distances)")
        if self.correction_band is not None and not self.min_readout:
            raise InputError("correction_band must be a positive length (m) and needs min_readout")
        if self.probe_split > 1 and not self.min_readout:
            raise InputError("probe_split must be ≥ 1, and > 1 needs min_readout")

    @classmethod
    def faithful(cls, **changes) -> GraphDistNetConfig:
        """The paper's network (§IV): one random, then the argmax partner per graph, two-way
        cross edges, no node distances, the plain readout, LeakyReLU."""
        return cls(cross="argmax", **changes)

    @classmethod
    def smooth(cls, **changes) -> GraphDistNetConfig:
        """The planner default: deterministic, continuous soft k-nearest partners."""
        return cls(cross="soft_knn", **changes)

    def to_dict(self) -> dict:
        """The card's ``config``; a paper-architecture card also names its first-layer draw
        (``random_pick = "graph"``): cards without it drew a partner per node (refused)."""
        out = asdict(self)
        return out | {"random_pick": "graph"} if self.cross == "argmax" else out

    @classmethod
    def from_dict(cls, data: dict) -> GraphDistNetConfig:
        """The architecture of a card's ``config`` (module docstring: loss weights of old flat
        cards are skipped, removed options accepted at their former default only)."""
        data = {k: v for k, v in dict(data).items() if k not in LOSS_KEYS}
        if data.get("cross") == "argmax" and "random_pick" not in data:
            raise InputError(
                "config: this paper-architecture card predates the paper's first layer (one "
                "random partner per graph) and drew one per node, an option that was removed; "
                "retrain it (gdnplan reproduce faithful)"
            )
        for key, default in REMOVED.items():
            value = data.pop(key, default)
            if value != default:
                raise InputError(
                    f"config: {key} = {value!r}: the option was removed (only its former "
                    f"default {default!r} is accepted); drop it from the config or retrain"
                )
        known = {f.name for f in fields(cls)}
        unknown = set(data) - known
        if unknown:
            raise InputError(f"config: unknown GraphDistNet options {sorted(unknown)}")
        return cls(**data)

    def with_(self, **changes) -> GraphDistNetConfig:
        """A copy with ``changes`` (architecture fields; InputError naming a loss weight)."""
        loss = sorted(set(changes) & set(LOSS_KEYS))
        if loss:
            raise InputError(
                f"config: {loss} are loss weights, not architecture; set them in "
                "gdnplan.train.GraphDistNetLoss"
            )
        return replace(self, **changes)


def _checked(c: GraphDistNetConfig) -> dict:
    """The fields of ``c`` checked (bounds: :mod:`gdnplan.models.fields`)."""
    band = c.correction_band
    return {
        "layers": check_int(c.layers, "layers", 1, MAX_LAYERS),
        "hidden": check_int(c.hidden, "hidden", 1, MAX_WIDTH),
        "mlp": check_widths("mlp", c.mlp),
        "readout": check_widths("readout", c.readout),
        "cross": check_choice("cross", c.cross, ("argmax", "soft_knn")),
        "cross_k": check_int(c.cross_k, "cross_k", 1, MAX_CROSS_K),
        "two_way": check_flag("two_way", c.two_way),
        "tau": check_real("tau", c.tau, MIN_TEMPERATURE, MAX_TEMPERATURE),
        "node_distance": check_flag("node_distance", c.node_distance),
        "min_readout": check_flag("min_readout", c.min_readout),
        "tau_min": check_real("tau_min", c.tau_min, MIN_TEMPERATURE, MAX_TEMPERATURE),
        "probe_split": check_int(c.probe_split, "probe_split", 1, MAX_PROBE_SPLIT),
        "correction_band": None
        if band is None
        else check_real("correction_band", band, MIN_LENGTH, MAX_LENGTH, " m"),
        "scale": check_real("scale", c.scale, MIN_LENGTH, MAX_LENGTH, " m"),
        "origin": check_point("origin", c.origin, 2),
    }


# Loss weights that old flat cards keep in their config (training settings now).
LOSS_KEYS = ("grad_weight", "grad_norm_weight", "contact_weight", "contact_scale")
# Removed options -> the one value they had in every card (accepted, and dropped).
REMOVED = {"activation": "leaky_relu", "max_edge": None, "random_pick": "graph"}
