"""GraphDistNet (paper §IV): message passing between a robot graph and an obstacle graph.

Notation (one sample): nodes i of the union graph G_ro = G_r ∪ G_o with coordinates x_i⁽⁰⁾
(normalised: (p − origin) / scale, scale = the arm's reach) and features x_i⁽ᵏ⁾ ∈ R^{d_h}.
Layer k = 0 … K − 1 updates every node with its ring neighbours N(i) = {prev(i), next(i)} and
one cross-graph partner j_c:

    x_i⁽ᵏ⁺¹⁾ = Σ_{j ∈ N(i) ∪ {i}} h_k( z_j⁽ᵏ⁾ − z_i⁽ᵏ⁾ ‖ z̄_i⁽ᵏ⁾ − z_i⁽ᵏ⁾ ),
    z_i⁽⁰⁾ = x_i⁽⁰⁾,  z_i⁽ᵏ⁾ = (x_i⁽⁰⁾ ‖ x_i⁽ᵏ⁾),                            (Eq. 2, 5)

h_k an MLP R^4 → R^{d_h} (k = 0), R^{2 d_h + 4} → R^{d_h} (k > 0). The cross term z̄_i:

* ``cross="argmax"`` (the paper): z̄_i = z_{j_c} with j_c uniform random over the other graph at
  k = 0, and j_c = argmax_j a⁽ᵏ⁾ᵀ x_j⁽ᵏ⁾ over the other graph afterwards (one partner per graph).
  d̂ is then random (k = 0) and jumps where the argmax switches.
* ``cross="soft_knn"`` (planner default): a soft partner among the k + 1 nearest nodes c of the
  other graph (squared distances d²_c in ascending order, d²_{k+1} the farthest of them):

      z̄_i = Σ_c w_ic z_c,  w_ic ∝ φ_ic exp(−d²_ic / τ_k + a⁽ᵏ⁾ᵀ x_c⁽ᵏ⁾),  φ_ic = d²_{k+1} − d²_ic,

  (no score at k = 0, τ_k learned). φ vanishes on the (k + 1)-th node, so a node entering or
  leaving the candidate set does so with zero weight: d̂ is a deterministic, continuous
  function of the node positions (and piecewise smooth).

One-way cross edges (``two_way=False``, beyond the paper): only robot nodes take a cross
partner; obstacle nodes have z̄_i = z_i (no cross term), so x_o⁽ᵏ⁾, their scores and their
readouts y_o⁽ᵏ⁾ depend on the scene alone. Inference computes them once per scene, and the
work per configuration is the robot graph's (N_r of N = N_r + N_o nodes) plus its soft
partners among the cached obstacle features.

Distance-aware nodes (``node_distance``, beyond the paper): every node also knows its signed
distance s_i to the other graph's polygons (:func:`signed_ring_distance`; robot nodes to the
obstacles, obstacle nodes to the links; normalised units, negative inside). h_k sees only
differences z_j − z_i, so s_i enters as an absolute per-node term of the first linear layer:
pre_ij = W_loc (z_j − z_i) + W_rel (z̄_i − z_i) + s_i w_k + b, the same on the three edges of i
(one-way networks: s = 0 on obstacle nodes, whose features stay scene-only). Between two
polygons that are apart the distance is min_i s_i (a closest pair has a vertex at one end), so
``min_readout`` reads d̂ as a correction of the soft minimum m = −τ_m log Σ_i exp(−s_i / τ_m):
d̂ = scale · (m + MLP(y_r ‖ y_o ‖ m)). The MLP then learns what m misses: penetration depth,
and overlaps without a vertex inside the other polygon (two thin bars crossing). s and m are
continuous in the node positions, so d̂ stays continuous. ``probe_split`` p adds the points
splitting every ring edge into p pieces to m's minimum (not to the graphs): a bar crossing a
square then has points inside it. ``correction_band`` β hands d̂ to m away from contact:
d̂ = scale · (g · MLP(…) + (1 − g) · m), g = σ(8 (1 − scale · m / β)) ≈ 1 in overlap and
< 3·10⁻⁴ once m is more than 2β apart, where d̂ is m itself (exact up to the soft minimum)
instead of the MLP's estimate; a network trained without m (head input m at weight 0) keeps
its function in overlap when it gets the band.

Readout (Eq. 9–11): per graph g ∈ {r, o} and layer k = 1 … K, α_i = softmax_{i∈g}(a⁽ᵏ⁾ᵀ x_i⁽ᵏ⁾),
y_g⁽ᵏ⁾ = f(Σ_i α_i x_i⁽ᵏ⁾); y_g = max_k y_g⁽ᵏ⁾ element-wise; d̂ = scale · MLP(y_r ‖ y_o) (m).

Implementation: dense padded tensors; the first linear layer of h_k is applied per node, not
per edge, since W (z_j − z_i) = W z_j − W z_i: with W = [W_loc W_rel] and u = z W_locᵀ,
v = z W_relᵀ (per node), the edge pre-activation is u_j − u_i + v̄_i − v_i + b.

Inference (:class:`GraphDistNetModel`, ``soft_knn``) runs :meth:`GraphDistNet.lean`, the same
function for one scene without padding: ring neighbours by one shared index, the cross terms
as dense batched products, the last linear layer of h_k after the sum over the edges and, for
LeakyReLU, the edge MLP with a hand-written backward (:class:`_LeakyRingMessages`). Tests
prove it equal to :meth:`GraphDistNet.forward` (values and gradients).
"""

from __future__ import annotations

import functools
import itertools
import math
import weakref
from collections.abc import Callable
from dataclasses import asdict, dataclass, fields, replace
from pathlib import Path

import numpy as np
import torch
from torch import nn

from ..errors import InputError
from ..graph import GraphBatch, RobotGraph, obstacle_graph, robot_graph, scene_obstacles
from ..scene import Scene
from .checks import build_net, card_config, check_count, check_fits
from .threads import check_threads, torch_threads
from .weights import read_weights

PAD_DIST2 = 1e6  # squared distance (normalised units²) given to padded candidates
LEAKY_SLOPE = 0.2  # negative slope of the paper's LeakyReLU
# graph nodes per inference pass: (d) two-way 80 configurations × 108 nodes, one-way 320 × 28
# were the fastest chunks on the 2-core Xeon (benchmarks/RESULTS.md)
CHUNK_NODES = 9000


@dataclass(frozen=True)
class GraphDistNetConfig:
    """Architecture, normalisation and loss options of GraphDistNet.

    Attributes:
        layers: K message-passing layers.
        hidden: d_h, node feature size.
        mlp: hidden widths of each h_k.
        readout: hidden widths of the final MLP.
        activation: ``"leaky_relu"`` (slope 0.2, the paper) or ``"silu"``.
        cross: ``"argmax"`` (paper: random, then argmax partner) or ``"soft_knn"``.
        cross_k: candidates k of ``soft_knn`` (k + 1 nearest nodes are looked at).
        two_way: cross edges into both graphs (the paper). False: only robot nodes take a
            cross partner (obstacle nodes have z̄_i = z_i), so the obstacle features depend on
            the scene alone and inference computes them once per scene (module docstring).
        tau: initial temperature τ of ``soft_knn`` (normalised units², learned per layer).
        max_edge: densify graph edges longer than this (m), or None.
        grad_weight: weight λ of the gradient loss λ · (1 − cos(∂d̂/∂q, ∂f/∂q)).
        grad_norm_weight: weight ν of the slope loss ν · ((|∂d̂/∂q| − |∂f/∂q|) / scale)²
            (trained with ``grad_weight`` > 0 only; the cosine leaves the slope free).
        contact_weight: extra weight μ of samples near contact in the distance loss,
            w = 1 + μ · exp(−|f| / contact_scale) (0 = paper: every sample alike).
        contact_scale: distance (m) over which the contact weight decays.
        node_distance: distance-aware nodes (beyond the paper): every layer's h_k also takes
            s_i, node i's signed distance to the other graph's polygons (normalised units,
            negative inside), as an absolute input (module docstring).
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
        scale: metres per normalised unit (the robot's reach); d̂ = scale · net output.
        origin: (x, y) subtracted from coordinates before scaling (joint 1, m).
    """

    layers: int = 4
    hidden: int = 32
    mlp: tuple[int, ...] = (32, 32, 32)
    readout: tuple[int, ...] = (32, 32, 32)
    activation: str = "leaky_relu"
    cross: str = "soft_knn"
    cross_k: int = 4
    two_way: bool = True
    tau: float = 0.02
    max_edge: float | None = None
    grad_weight: float = 0.0
    grad_norm_weight: float = 0.0
    contact_weight: float = 0.0
    contact_scale: float = 0.02
    node_distance: bool = False
    min_readout: bool = False
    tau_min: float = 1e-3
    probe_split: int = 1
    correction_band: float | None = None
    scale: float = 1.0
    origin: tuple[float, float] = (0.0, 0.0)

    def __post_init__(self) -> None:
        for f in fields(self):
            value = getattr(self, f.name)
            if any(isinstance(v, float) and not math.isfinite(v) for v in np.ravel(value)):
                raise InputError(f"{f.name}: expected finite numbers, got {value!r}")
        if self.activation not in ("leaky_relu", "silu"):
            raise InputError(
                f"activation: expected 'leaky_relu' or 'silu', got {self.activation!r}"
            )
        if self.cross not in ("argmax", "soft_knn"):
            raise InputError(f"cross: expected 'argmax' or 'soft_knn', got {self.cross!r}")
        if self.layers < 1 or self.hidden < 1 or self.cross_k < 1 or self.scale <= 0:
            raise InputError("layers, hidden, cross_k and scale must be positive")
        if self.grad_norm_weight < 0 or (self.grad_norm_weight > 0 and self.grad_weight <= 0):
            raise InputError("grad_norm_weight must be ≥ 0, and needs grad_weight > 0")
        if self.contact_weight < 0 or self.contact_scale <= 0:
            raise InputError("contact_weight must be ≥ 0 and contact_scale positive")
        if self.min_readout and not self.node_distance:
            raise InputError("min_readout needs node_distance=True (it reads the node distances)")
        if self.tau_min <= 0:
            raise InputError(f"tau_min: expected a positive temperature, got {self.tau_min}")
        if self.correction_band is not None and (self.correction_band <= 0 or not self.min_readout):
            raise InputError("correction_band must be a positive length (m) and needs min_readout")
        if self.probe_split < 1 or (self.probe_split > 1 and not self.min_readout):
            raise InputError("probe_split must be ≥ 1, and > 1 needs min_readout")

    @classmethod
    def faithful(cls, **changes) -> GraphDistNetConfig:
        """The paper's network: random/argmax partners, LeakyReLU, distance loss only."""
        return cls(cross="argmax", **changes)

    @classmethod
    def smooth(cls, **changes) -> GraphDistNetConfig:
        """The planner default: deterministic, continuous soft k-nearest partners."""
        return cls(cross="soft_knn", **changes)

    def to_dict(self) -> dict:
        return asdict(self)

    @classmethod
    def from_dict(cls, data: dict) -> GraphDistNetConfig:
        known = {f.name for f in fields(cls)}
        unknown = set(data) - known
        if unknown:
            raise InputError(f"config: unknown GraphDistNet options {sorted(unknown)}")
        data = dict(data)
        for key in ("mlp", "readout", "origin"):
            if key in data:
                data[key] = tuple(data[key])
        return cls(**data)

    def with_(self, **changes) -> GraphDistNetConfig:
        return replace(self, **changes)


def _activation(name: str) -> nn.Module:
    return nn.LeakyReLU(LEAKY_SLOPE) if name == "leaky_relu" else nn.SiLU()


def mlp(sizes: list[int], activation: str) -> nn.Sequential:
    """Linear layers of ``sizes`` with the activation between them (none after the last)."""
    mods: list[nn.Module] = []
    for i, (a, b) in enumerate(itertools.pairwise(sizes)):
        mods.append(nn.Linear(a, b))
        if i < len(sizes) - 2:
            mods.append(_activation(activation))
    return nn.Sequential(*mods)


def masked_softmax(logits: torch.Tensor, mask: torch.Tensor, dim: int = -1) -> torch.Tensor:
    """Softmax over ``dim`` with masked-out entries at zero weight."""
    return torch.softmax(logits.masked_fill(~mask, -math.inf), dim)


def nearest_candidates(d2: torch.Tensor, c: int) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
    """The c nearest nodes of the other graph for every union node, robot nodes first.

    Args:
        d2: (B, N_r, N_o) squared distances between robot and obstacle nodes.
        c: candidates per node (capped at the larger graph's size).

    Returns:
        idx (B, N, C) union indices (obstacles shifted by N_r), log φ (B, N, C) with
        φ_c = d²_C − d²_c (−∞ on padding when the other graph has fewer than C nodes) and the
        candidates' d² (B, N, C), ascending.
    """
    n_r = d2.shape[1]
    c = min(c, max(d2.shape[1:]))
    out = []
    for dist, offset in ((d2, n_r), (d2.transpose(1, 2), 0)):
        idx, log_phi, near = nearest_columns(dist, c)
        out.append((idx + offset, log_phi, near))
    return tuple(torch.cat(parts, 1) for parts in zip(*out, strict=True))


def nearest_columns(dist: torch.Tensor, c: int) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
    """Column indices (B, n, c), log φ (B, n, c) and values (B, n, c) of the c smallest entries of
    every row of ``dist`` (B, n, m), ascending; padded with zero-weight (log φ = −∞) candidates
    when m < c. φ_c = d²_c_max − d²_c as in :func:`nearest_candidates`."""
    kk = min(c, dist.shape[-1])
    near, idx = torch.topk(dist, kk, dim=-1, largest=False)  # ascending
    log_phi = (near[..., -1:] - near).clamp_min(1e-12).log()
    if kk < c:  # a small other graph: pad with zero-weight candidates
        pad = (0, c - kk)
        near = nn.functional.pad(near, pad, value=PAD_DIST2)
        log_phi = nn.functional.pad(log_phi, pad, value=-math.inf)
        idx = nn.functional.pad(idx, pad)
    return idx, log_phi, near


def nearest_obstacle_nodes(
    xr: torch.Tensor, xo: torch.Tensor, c: int
) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
    """:func:`nearest_columns` of the robot–obstacle squared distances, c ≤ N_o, with a sparse
    gradient.

    The c nearest obstacle nodes are chosen on the dense (B, N_r, N_o) distances without
    autograd; their d²_c = |x_r − x_o,c|² are then recomputed from the (B, N_r, c, 2) differences
    (the same floating-point operations, so the same values): the backward pass touches c
    candidates per robot node instead of all N_o obstacle nodes.

    Args:
        xr: (B, N_r, 2) robot nodes; xo: (N_o, 2) obstacle nodes (normalised units).
    """
    with torch.no_grad():
        idx = torch.topk(_pairwise_d2(xr, xo), c, dim=-1, largest=False).indices  # ascending
    diff = xr[..., None, :] - xo[idx]
    near = (diff * diff).sum(-1)
    return idx, (near[..., -1:] - near).clamp_min(1e-12).log(), near


def _softmax_small(logits: torch.Tensor) -> torch.Tensor:
    """Softmax over a short last dimension (the C candidates): exp(l − max l) / Σ exp(l − max l).

    The same function as :func:`torch.softmax`, several times faster than it for C ≈ 5 on CPU;
    the shift max l is a constant to autograd (the softmax does not depend on it).
    """
    e = (logits - logits.detach().amax(-1, keepdim=True)).exp()
    return e / e.sum(-1, keepdim=True)


def _pairwise_d2(xr: torch.Tensor, xo: torch.Tensor) -> torch.Tensor:
    """(B, N_r, N_o) squared distances between robot nodes xr (B, N_r, 2) and obstacle nodes
    xo (N_o, 2): (x_r − x_o)² + (y_r − y_o)², the same floating-point operations as summing
    the squared differences over the last axis, in half the memory passes."""
    dx = xr[..., 0, None] - xo[:, 0]
    dy = xr[..., 1, None] - xo[:, 1]
    return dx * dx + dy * dy


def signed_ring_distance(
    points: torch.Tensor, nodes: torch.Tensor, next: torch.Tensor, mask: torch.Tensor | None = None
) -> torch.Tensor:
    """Signed distance (B, P) of points (B, P, 2) to the union of counter-clockwise rings.

    Rings: nodes (B, M, 2) (or (1, M, 2), shared), next (B, M) and mask (B, M) (None: every
    node is real); edge m runs from a_m to b_m = a_next(m). The distance is to the nearest edge,

        δ_pm = |p − a_m − t e_m|,  e_m = b_m − a_m,  t = clamp((p − a_m)·e_m / |e_m|², 0, 1),

    s_p = ± min_m δ_pm, negative where p is inside a ring (non-zero winding number: edges
    crossing the ray p + λ x̂, λ > 0, counted +1 upwards with p on their left, −1 downwards
    with p on their right). s is continuous in p and in the nodes (the sign switches where
    min δ = 0); masked edges are left out. Between two apart polygons the distance is the
    smallest |s| over the vertices of both, since a closest pair has a vertex at one end.

    The nearest edge and the winding number are found without autograd over all (P, M)
    pairs; δ is then recomputed, differentiably, for the nearest edge only (the gradient of
    a minimum is its minimiser's), so the backward pass costs O(B P), not O(B P M).
    """
    b = points.shape[0]
    ends = torch.gather(nodes, 1, next[..., None].expand(*next.shape, 2))
    edges = ends - nodes  # (B or 1, M, 2)
    edge_mask = None if mask is None else mask[:, None]
    d2_min, nearest, inside = _nearest_edge_and_inside(
        points.detach(), nodes[:, None].detach(), edges[:, None].detach(), edge_mask
    )
    pick = nearest[..., None].expand(*nearest.shape, 2)
    a = torch.gather(nodes.expand(b, -1, -1), 1, pick)  # (B, P, 2)
    e = torch.gather(edges.expand(b, -1, -1), 1, pick)
    w = points - a
    t = ((w * e).sum(-1) / (e * e).sum(-1).clamp_min(1e-12)).clamp(0.0, 1.0)
    dist = (w - t[..., None] * e).square().sum(-1).clamp_min(1e-12).sqrt()
    dist = torch.where(d2_min < PAD_DIST2, dist, math.sqrt(PAD_DIST2))  # every edge masked
    return torch.where(inside, -dist, dist)


@torch.no_grad()
def _nearest_edge_and_inside(
    points: torch.Tensor, a: torch.Tensor, e: torch.Tensor, mask: torch.Tensor | None
) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
    """For points (B, P, 2) and edges a_m + t e_m given by a and e (B or 1, P or 1, M, 2),
    masked edges (mask broadcastable to (B, P, M)) left out: the smallest squared distance
    min_m δ²_pm (B, P), its edge m (B, P), and whether the winding number around p is
    non-zero (B, P) (see :func:`signed_ring_distance`).

    x and y are separate contiguous (B, P, M) tensors (no reductions over a trailing 2)."""
    ax, ay = a[..., 0].contiguous(), a[..., 1].contiguous()
    ex, ey = e[..., 0].contiguous(), e[..., 1].contiguous()
    wx = points[..., 0, None] - ax  # (B, P, M)
    wy = points[..., 1, None] - ay
    inv = (ex * ex + ey * ey).clamp_min_(1e-12).reciprocal_()
    t = (wx * ex).add_(wy * ey).mul_(inv).clamp_(0.0, 1.0)
    d2 = (wx - t * ex).square_().add_((wy - t * ey).square_())
    if mask is not None:
        d2 = d2.masked_fill_(~mask, PAD_DIST2)
    d2_min, nearest = d2.min(-1)
    left = (ex * wy).sub_(ey * wx)  # e × (p − a) > 0: p left of the edge
    up = (wy >= 0) & (wy < ey)  # a_y ≤ p_y < b_y
    down = (wy < 0) & (wy >= ey)  # b_y ≤ p_y < a_y
    winding = (up & (left > 0)).int() - (down & (left < 0)).int()
    if mask is not None:
        winding = winding.masked_fill(~mask, 0)
    return d2_min, nearest, winding.sum(-1) != 0


def _cross_mix(idx: torch.Tensor, w: torch.Tensor, n_r: int) -> tuple[torch.Tensor, torch.Tensor]:
    """Dense cross weights: M_ro (B, N_r, N_o) and M_or (B, N_o, N_r), (M)_ij = Σ_{c: j_c = j} w_ic.

    Σ_c w_ic v_{j_c} is then row i of M_ro v_o (robot nodes i) or M_or v_r (obstacle nodes):
    a batched matrix product instead of a (B, N, C, d_h) gather (faster on CPU).

    Args:
        idx: (B, N, C) union indices of the candidates (robot nodes first); w: (B, N, C).
    """
    b, n, _ = idx.shape
    n_o = n - n_r
    m_ro = w.new_zeros(b, n_r, n_o).scatter_add_(-1, idx[:, :n_r] - n_r, w[:, :n_r])
    m_or = w.new_zeros(b, n_o, n_r).scatter_add_(-1, idx[:, n_r:], w[:, n_r:])
    return m_ro, m_or


class _LeakyRingMessages(torch.autograd.Function):
    """Σ_e g(pre_e) (B, N, H) over the edges e = (prev, next, self) of every node, in place.

    pre_prev/next = u_j − u_i + c_i, pre_self = c_i and g = σ ∘ L_m ∘ σ ∘ … ∘ L_1 ∘ σ with
    σ = LeakyReLU(0.2) and the hidden linear layers L_l = (W_l, b_l) of h_k. The activations
    are applied in place and kept (σ(s) > 0 ⇔ s > 0), and the backward pass reuses its
    buffers: ∂/∂s = σ'(s) ⊙ ∂/∂σ(s), ∂/∂a = (∂/∂s) W. Gradients flow to u and c only
    (inference: the weights get none).
    """

    @staticmethod
    def forward(ctx, u: torch.Tensor, c: torch.Tensor, ring: torch.Tensor, *weights: torch.Tensor):
        b, n, hd = u.shape
        pre = u.new_empty(b, 3, n, hd)
        torch.add(u.index_select(1, ring).view(b, 2, n, hd), (c - u)[:, None], out=pre[:, :2])
        pre[:, 2] = c
        acts = [nn.functional.leaky_relu_(pre, LEAKY_SLOPE)]
        for w, bias in zip(weights[::2], weights[1::2], strict=True):
            # a product then an in-place bias: faster than linear's addmm, which first copies the
            # broadcast bias into its (B·3·N, H) output
            acts.append(nn.functional.leaky_relu_((acts[-1] @ w.T).add_(bias), LEAKY_SLOPE))
        ctx.save_for_backward(ring, *weights[::2], *acts)
        return acts[-1].sum(1)

    @staticmethod
    def backward(ctx, grad: torch.Tensor):
        ring, *saved = ctx.saved_tensors
        n_lin = len(saved) // 2
        ws, acts = saved[:n_lin], saved[n_lin:]
        g = torch.ops.aten.leaky_relu_backward(
            grad[:, None].expand_as(acts[-1]), acts[-1], LEAKY_SLOPE, True
        )
        for w, a in zip(reversed(ws), reversed(acts[:-1]), strict=True):
            g = g @ w
            torch.ops.aten.leaky_relu_backward.grad_input(g, a, LEAKY_SLOPE, True, grad_input=g)
        b, _, n, hd = g.shape
        ring_grad = g[:, :2]
        u_grad = (-ring_grad.sum(1)).index_add_(1, ring, ring_grad.reshape(b, 2 * n, hd))
        return (u_grad, g.sum(1), None, *(None for _ in range(2 * n_lin)))


@dataclass(frozen=True)
class Union:
    """The union graph G_ro of a batch: N = N_r + N_o nodes (robot nodes first).

    Attributes:
        x0: (B, N, 2) normalised coordinates.
        nbr: (B, N, 3) neighbour indices (prev, next, self).
        mask: (B, N) real nodes.
        n_robot: N_r.
    """

    x0: torch.Tensor
    nbr: torch.Tensor
    mask: torch.Tensor
    n_robot: int


@dataclass(frozen=True)
class ObstacleFeatures:
    """What one-way cross edges (``two_way=False``) need of a scene's obstacle graph, per layer
    k = 0 … K − 1; it depends on the scene alone.

    Attributes:
        v: (K, N_o, d_h) W_rel,k z_o⁽ᵏ⁾, the partner terms robot nodes mix at layer k.
        score: (K, N_o) a⁽ᵏ⁾ᵀ x_o⁽ᵏ⁾ added to the partner logits of layer k (row 0: zeros).
        readout: (K, d_h) the obstacle graph's readout y_o⁽ᵏ⁺¹⁾.
    """

    v: torch.Tensor
    score: torch.Tensor
    readout: torch.Tensor


@dataclass(frozen=True)
class SceneGraph:
    """The constants of one scene for :meth:`GraphDistNet.lean` (no padding).

    Attributes:
        obstacles: (N_o, 2) normalised obstacle node coordinates.
        ring: (2 N,) union index of prev(i) for every node i, then of next(i) (robot first).
        robot_ring: (2 N_r,) the same for the robot graph alone.
        fixed: the obstacle graph's features (``two_way=False``), else None.
    """

    obstacles: torch.Tensor
    ring: torch.Tensor
    robot_ring: torch.Tensor
    fixed: ObstacleFeatures | None = None

    @property
    def robot_next(self) -> torch.Tensor:
        """(N_r,) robot-graph index of every robot node's ring successor."""
        return self.robot_ring[len(self.robot_ring) // 2 :]

    @property
    def obstacle_next(self) -> torch.Tensor:
        """(N_o,) obstacle-graph index of every obstacle node's ring successor."""
        n_r = len(self.ring) // 2 - len(self.obstacles)
        return self.ring[len(self.ring) // 2 + n_r :] - n_r


class GraphDistNet(nn.Module):
    """The network of :class:`GraphDistNetConfig`; ``forward(robot, obstacles) -> d̂ (B,)`` (m)."""

    def __init__(self, config: GraphDistNetConfig):
        super().__init__()
        self.config = config
        c = config
        self.convs = nn.ModuleList()
        for k in range(c.layers):
            d_in = 2 if k == 0 else 2 + c.hidden  # size of z_i
            self.convs.append(mlp([2 * d_in, *c.mlp, c.hidden], c.activation))
        self.attention = nn.Parameter(torch.randn(c.layers, c.hidden) / math.sqrt(c.hidden))
        self.log_tau = nn.Parameter(torch.full((c.layers,), math.log(c.tau)))
        self.head = mlp([2 * c.hidden + int(c.min_readout), *c.readout, 1], c.activation)
        self.out_act = _activation(c.activation)
        if c.node_distance:  # w_k: s_i w_k joins the first linear layer of h_k on every edge
            width = (c.mlp or (c.hidden,))[0]
            self.distance_in = nn.Parameter(torch.empty(c.layers, width).uniform_(-1.0, 1.0))
        if c.min_readout:
            self.log_tau_min = nn.Parameter(torch.tensor(math.log(c.tau_min)))
            nn.init.zeros_(self.head[-1].weight)  # d̂ = scale · m at initialisation
            nn.init.zeros_(self.head[-1].bias)

    # ------------------------------------------------------------------ graph plumbing
    def union(self, robot: GraphBatch, obstacles: GraphBatch) -> Union:
        """Normalise coordinates and join both graphs (obstacle indices shifted by N_r)."""
        c = self.config
        origin = torch.as_tensor(c.origin, dtype=robot.nodes.dtype, device=robot.nodes.device)
        x0 = (torch.cat([robot.nodes, obstacles.nodes], 1) - origin) / c.scale
        n_r, n = robot.nodes.shape[1], robot.nodes.shape[1] + obstacles.nodes.shape[1]
        prev = torch.cat([robot.prev, obstacles.prev + n_r], 1)
        next = torch.cat([robot.next, obstacles.next + n_r], 1)
        own = torch.arange(n, device=x0.device).expand(x0.shape[0], -1)
        nbr = torch.stack([prev, next, own], -1)
        return Union(x0, nbr, torch.cat([robot.mask, obstacles.mask], 1), n_r)

    def candidates(self, g: Union) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
        """Soft-kNN candidates of every node in the other graph.

        Returns:
            idx (B, N, C) candidate indices into the union, log φ (B, N, C) and d² (B, N, C),
            C = min(k + 1, size of the larger graph); missing candidates have log φ = −∞.
        """
        n_r = g.n_robot
        xr, xo = g.x0[:, :n_r], g.x0[:, n_r:]
        d2 = (xr[:, :, None] - xo[:, None]).square().sum(-1)  # (B, N_r, N_o), twice differentiable
        d2 = d2.masked_fill(~g.mask[:, None, n_r:], PAD_DIST2)
        d2 = d2.masked_fill(~g.mask[:, :n_r, None], PAD_DIST2)
        return nearest_candidates(d2, self.config.cross_k + 1)

    def node_distances(self, g: Union) -> torch.Tensor | None:
        """(B, N) s_i of ``node_distance`` networks (:func:`signed_ring_distance`, normalised
        units; robot nodes to the obstacle polygons, obstacle nodes to the link polygons, 0 on
        padding and, for one-way networks, on obstacle nodes); None for other networks."""
        if not self.config.node_distance:
            return None
        n_r = g.n_robot
        nxt = g.nbr[..., 1]
        xr, xo = g.x0[:, :n_r], g.x0[:, n_r:]
        s_r = signed_ring_distance(xr, xo, nxt[:, n_r:] - n_r, g.mask[:, n_r:])
        if self.config.two_way:
            s_o = signed_ring_distance(xo, xr, nxt[:, :n_r], g.mask[:, :n_r])
        else:
            s_o = xo.new_zeros(xo.shape[:2])
        return torch.cat([s_r, s_o], 1) * g.mask

    def partners_argmax(
        self, g: Union, h: torch.Tensor | None, k: int, generator: torch.Generator | None
    ) -> torch.Tensor:
        """(B, N) paper partners: random at k = 0, else argmax of a⁽ᵏ⁾ᵀ x⁽ᵏ⁾ in the other graph."""
        b, n = g.mask.shape
        n_r = g.n_robot
        valid_r = g.mask[:, :n_r].sum(1, keepdim=True)  # valid nodes come first in each graph
        valid_o = g.mask[:, n_r:].sum(1, keepdim=True)
        is_robot = torch.arange(n, device=g.mask.device) < n_r
        if h is None:
            u = torch.rand(b, n, generator=generator, device=g.mask.device)
            pick_o = n_r + (u * valid_o).long().clamp_max(valid_o - 1)
            pick_r = (u * valid_r).long().clamp_max(valid_r - 1)
            return torch.where(is_robot, pick_o, pick_r)
        score = (h @ self.attention[k - 1]).masked_fill(~g.mask, -math.inf)
        best_r = score[:, :n_r].argmax(1, keepdim=True)
        best_o = n_r + score[:, n_r:].argmax(1, keepdim=True)
        return torch.where(is_robot, best_o, best_r)

    def cross_weights(
        self,
        g: Union,
        h: torch.Tensor | None,
        k: int,
        cand: tuple[torch.Tensor, torch.Tensor, torch.Tensor] | None,
        generator: torch.Generator | None,
    ) -> tuple[torch.Tensor, torch.Tensor]:
        """Partners (B, N, C) and weights (B, N, C), Σ_c w = 1, of conv layer k (h = x⁽ᵏ⁾)."""
        if self.config.cross == "argmax":
            idx = self.partners_argmax(g, h, k, generator)[..., None]
            return idx, torch.ones(idx.shape, dtype=g.x0.dtype, device=g.x0.device)
        idx, log_phi, d2 = cand
        logits = log_phi - d2 / self.log_tau[k].exp()
        if h is not None:
            score = h @ self.attention[k - 1]  # a⁽ᵏ⁾ scores x⁽ᵏ⁾, k ≥ 1
            logits = logits + torch.gather(score, 1, idx.flatten(1)).view(idx.shape)
        return idx, torch.softmax(logits, -1)

    def edge_preactivation(
        self,
        k: int,
        z: torch.Tensor,
        nbr: torch.Tensor,
        idx: torch.Tensor,
        w: torch.Tensor,
        one_way_from: int | None = None,
        s: torch.Tensor | None = None,
    ) -> torch.Tensor:
        """First linear layer of h_k on every edge, computed per node.

        Args:
            z: (B, N, D) node inputs z_i.
            nbr: (B, N, 3) neighbours (prev, next, self).
            idx, w: (B, N, C) cross partners and weights.
            one_way_from: nodes from this index on (the obstacles) take no cross term
                (z̄_i = z_i, ``two_way=False``); None: every node takes one.
            s: (B, N) node distances s_i (``node_distance``), or None.

        Returns:
            (B, N, 3, H): W_loc (z_j − z_i) + W_rel (Σ_c w_ic z_c − z_i) + s_i w_k + b.
        """
        first = self.convs[k][0]
        d = z.shape[-1]
        u = z @ first.weight[:, :d].T  # (B, N, H)
        v = z @ first.weight[:, d:].T
        b, n, h = u.shape
        u_j = torch.gather(u, 1, nbr.flatten(1)[..., None].expand(-1, -1, h)).view(b, n, 3, h)
        v_c = torch.gather(v, 1, idx.flatten(1)[..., None].expand(-1, -1, h))
        v_bar = (w[:, :, None] @ v_c.view(b, n, -1, h)).squeeze(2)  # Σ_c w_ic v_c
        if one_way_from is not None:
            v_bar = torch.cat([v_bar[:, :one_way_from], v[:, one_way_from:]], 1)
        return u_j - u[:, :, None] + self._node_term(k, v_bar - v + first.bias, s)[:, :, None]

    def _node_term(self, k: int, c: torch.Tensor, s: torch.Tensor | None) -> torch.Tensor:
        """c (B, N, H) + s_i w_k (``node_distance``; s (B, N)), or c when s is None."""
        return c if s is None else torch.addcmul(c, s[..., None], self.distance_in[k])

    def readout(self, g: Union, h: torch.Tensor, k: int) -> torch.Tensor:
        """(B, 2 d_h): f(Σ α_i x_i⁽ᵏ⁾) for the robot graph, then the obstacle graph (k ≥ 1)."""
        score = h @ self.attention[k - 1]
        ys = []
        for sl in (slice(0, g.n_robot), slice(g.n_robot, None)):
            alpha = masked_softmax(score[:, sl], g.mask[:, sl])
            ys.append(self.out_act((alpha[..., None] * h[:, sl]).sum(1)))
        return torch.cat(ys, -1)

    # ------------------------------------------------------------------ forward
    def forward(
        self, robot: GraphBatch, obstacles: GraphBatch, generator: torch.Generator | None = None
    ) -> torch.Tensor:
        """Estimated signed distance d̂ (B,) in metres.

        Args:
            robot: robot graphs (B, N_r) at the configurations (coordinates in m).
            obstacles: obstacle graphs (B, N_o) (m).
            generator: random source of the first-layer partners (``cross="argmax"`` only).
        """
        g = self.union(robot, obstacles)
        cand = self.candidates(g) if self.config.cross == "soft_knn" else None
        one_way = None if self.config.two_way else g.n_robot
        s = self.node_distances(g)
        h = None
        pooled = None
        for k in range(self.config.layers):
            z = g.x0 if h is None else torch.cat([g.x0, h], -1)
            idx, w = self.cross_weights(g, h, k, cand, generator)
            pre = self.edge_preactivation(k, z, g.nbr, idx, w, one_way, s)
            h = self.convs[k][1:](pre).sum(2) * g.mask[..., None]
            y = self.readout(g, h, k + 1)
            pooled = y if pooled is None else torch.maximum(pooled, y)
        if not self.config.min_readout:
            return self.estimate(pooled)
        n_r, nxt = g.n_robot, g.nbr[..., 1]
        probes = self.probe_distances(
            g.x0[:, :n_r],
            g.x0[:, n_r:],
            nxt[:, :n_r],
            nxt[:, n_r:] - n_r,
            g.mask[:, :n_r],
            g.mask[:, n_r:],
        )
        s, mask = (s, g.mask) if one_way is None else (s[:, :one_way], g.mask[:, :one_way])
        probe_mask = mask.repeat_interleave(self.config.probe_split - 1, 1)  # a probe's node
        return self.estimate(pooled, torch.cat([s, probes], 1), torch.cat([mask, probe_mask], 1))

    def probe_distances(
        self,
        xr: torch.Tensor,
        xo: torch.Tensor,
        next_r: torch.Tensor,
        next_o: torch.Tensor,
        mask_r: torch.Tensor | None = None,
        mask_o: torch.Tensor | None = None,
    ) -> torch.Tensor:
        """Signed distances (B, P) of the ``probe_split`` points.

        The points a_i + (t/p)(b_i − a_i), t = 1 … p − 1, of every ring edge a_i → b_i =
        a_next(i) of the robot nodes xr (B, N_r, 2) (to the obstacle rings) and, for two-way
        networks, of the obstacle nodes xo (B or 1, N_o, 2) (to the links), node by node in
        the order of the nodes; next_r/next_o (B or 1, N) index each graph's own nodes; the
        masks (None: all valid) leave out padded edges. P = 0 for p = 1.
        """
        split = self.config.probe_split
        b = xr.shape[0]
        if split == 1:
            return xr.new_zeros(b, 0)
        t = torch.arange(1, split, dtype=xr.dtype, device=xr.device) / split

        def points(x: torch.Tensor, nxt: torch.Tensor) -> torch.Tensor:
            ends = torch.gather(x, 1, nxt[..., None].expand(*nxt.shape, 2))
            return (x[:, :, None] + t[:, None] * (ends - x)[:, :, None]).flatten(1, 2)

        s = signed_ring_distance(points(xr, next_r), xo, next_o, mask_o)
        if not self.config.two_way:
            return s
        s_o = signed_ring_distance(points(xo, next_o).expand(b, -1, -1), xr, next_r, mask_r)
        return torch.cat([s, s_o], 1)

    def estimate(
        self,
        pooled: torch.Tensor,
        s: torch.Tensor | None = None,
        mask: torch.Tensor | None = None,
    ) -> torch.Tensor:
        """d̂ (B,) (m) of the pooled readouts (B, 2 d_h): scale · MLP(y_r ‖ y_o), or with
        ``min_readout`` scale · (m + MLP(y_r ‖ y_o ‖ m)), m the soft minimum of the signed
        distances s (B, P) (nodes, then probe points) over ``mask`` (B, P) (None: all), or
        with ``correction_band`` β scale · (g · MLP(…) + (1 − g) · m), g = σ(8 (1 − scale ·
        m / β)). One-way networks pass the robot nodes only (obstacle nodes have no s_i)."""
        if not self.config.min_readout:
            return self.head(pooled).squeeze(-1) * self.config.scale
        tau = self.log_tau_min.exp()
        logits = -s / tau
        if mask is not None:
            logits = logits.masked_fill(~mask, -math.inf)
        m = -tau * torch.logsumexp(logits, -1, keepdim=True)
        mlp = self.head(torch.cat([pooled, m], -1))
        band = self.config.correction_band
        if band is None:
            return (m + mlp).squeeze(-1) * self.config.scale
        gate = torch.sigmoid(8 * (1 - m * (self.config.scale / band)))
        return (m + gate * (mlp - m)).squeeze(-1) * self.config.scale

    # ------------------------------------------------------------------ lean inference
    def scene_graph(self, robot: RobotGraph, obstacles: GraphBatch) -> SceneGraph:
        """The :class:`SceneGraph` of a robot graph and one unpadded obstacle graph (1, N_o).

        With ``two_way=False`` it holds the obstacle features of the current weights.
        """
        c = self.config
        xo = obstacles.nodes[0]
        xo = (xo - xo.new_tensor(c.origin)) / c.scale
        n_r = robot.n_nodes
        robot_prev, robot_next = torch.as_tensor(robot.prev), torch.as_tensor(robot.next)
        prev = torch.cat([robot_prev, obstacles.prev[0].cpu() + n_r])
        next = torch.cat([robot_next, obstacles.next[0].cpu() + n_r])
        obstacle_ring = torch.cat([obstacles.prev[0], obstacles.next[0]]).to(xo.device)
        return SceneGraph(
            xo,
            torch.cat([prev, next]).to(xo.device),
            torch.cat([robot_prev, robot_next]).to(xo.device),
            None if c.two_way else self.obstacle_features(xo, obstacle_ring),
        )

    @torch.no_grad()
    def obstacle_features(self, xo: torch.Tensor, ring: torch.Tensor) -> ObstacleFeatures:
        """:class:`ObstacleFeatures` of normalised obstacle nodes (N_o, 2) with ring (2 N_o,):
        the K layers run on the obstacle graph alone, every z̄_i = z_i."""
        x0 = xo[None]
        h = None
        v, score, readout = [], [torch.zeros_like(xo[:, 0])], []
        for k in range(self.config.layers):
            z = x0 if h is None else torch.cat([x0, h], -1)
            v.append((z @ self.convs[k][0].weight[:, z.shape[-1] :].T)[0])
            h = self._lean_conv(k, z, lambda v_own: v_own, ring)
            s = h @ self.attention[k]
            score.append(s[0])
            readout.append(self._lean_pool(h, s)[0])
        return ObstacleFeatures(torch.stack(v), torch.stack(score[:-1]), torch.stack(readout))

    def lean(self, nodes: torch.Tensor, scene: SceneGraph) -> torch.Tensor:
        """d̂ (B,) (m) of robot nodes (B, N_r, 2) (m) among one scene's obstacles.

        The function of :meth:`forward` for ``cross="soft_knn"`` without padding, reorganised
        for inference: ring neighbours are gathered with one index shared by the batch, the
        cross terms Σ_c w_ic v_c are two dense products (:func:`_cross_mix`), a⁽ᵏ⁾ᵀ x⁽ᵏ⁾ is
        computed once for the readout and the next layer's partners, and the last linear layer
        (W, b) of h_k is applied once per node to the sum of the three edges' activations a_e:
        Σ_e (W a_e + b) = W Σ_e a_e + 3 b. One-way networks run :meth:`lean_one_way`.
        """
        if scene.fixed is not None:
            return self.lean_one_way(nodes, scene)
        c = self.config
        b, n_r, _ = nodes.shape
        xr = (nodes - nodes.new_tensor(c.origin)) / c.scale
        x0 = torch.cat([xr, scene.obstacles.expand(b, -1, -1)], 1)
        n = x0.shape[1]
        d2 = _pairwise_d2(xr, scene.obstacles)
        idx, log_phi, near = nearest_candidates(d2, c.cross_k + 1)
        s = self._lean_distances(xr, scene)
        rows = idx + n * torch.arange(b, device=idx.device)[:, None, None]  # rows of (B N)
        h, score, pooled = None, None, None
        for k in range(c.layers):
            logits = log_phi - near / self.log_tau[k].exp()
            if score is not None:
                logits = logits + score.flatten()[rows]
            z = x0 if h is None else torch.cat([x0, h], -1)
            m_ro, m_or = _cross_mix(idx, _softmax_small(logits), n_r)

            def mix(v: torch.Tensor, m_ro=m_ro, m_or=m_or) -> torch.Tensor:
                return torch.cat([m_ro @ v[:, n_r:], m_or @ v[:, :n_r]], 1)

            h = self._lean_conv(k, z, mix, scene.ring, s)
            score = h @ self.attention[k]
            y = torch.cat(
                [
                    self._lean_pool(h[:, :n_r], score[:, :n_r]),
                    self._lean_pool(h[:, n_r:], score[:, n_r:]),
                ],
                -1,
            )
            pooled = y if pooled is None else torch.maximum(pooled, y)
        return self._lean_estimate(pooled, xr, scene, s)

    def lean_one_way(self, nodes: torch.Tensor, scene: SceneGraph) -> torch.Tensor:
        """:meth:`lean` for ``two_way=False``: only the robot graph runs per configuration;
        partner terms, partner scores and the obstacle readout come from ``scene.fixed``."""
        c, fixed = self.config, scene.fixed
        b, n_o = nodes.shape[0], len(scene.obstacles)
        xr = (nodes - nodes.new_tensor(c.origin)) / c.scale
        idx, log_phi, near = nearest_obstacle_nodes(xr, scene.obstacles, min(c.cross_k + 1, n_o))
        s = self._lean_distances(xr, scene)
        h, pooled = None, None
        for k in range(c.layers):
            logits = log_phi - near / self.log_tau[k].exp()
            if k:
                logits = logits + fixed.score[k].take(idx)
            w = _softmax_small(logits)
            m_ro = w.new_zeros(*idx.shape[:2], n_o).scatter_add_(-1, idx, w)  # (B, N_r, N_o)

            def mix(v: torch.Tensor, m_ro=m_ro, v_o=fixed.v[k]) -> torch.Tensor:
                return m_ro @ v_o

            z = xr if h is None else torch.cat([xr, h], -1)
            h = self._lean_conv(k, z, mix, scene.robot_ring, s)
            y_r = self._lean_pool(h, h @ self.attention[k])
            y = torch.cat([y_r, fixed.readout[k].expand(b, -1)], -1)
            pooled = y if pooled is None else torch.maximum(pooled, y)
        return self._lean_estimate(pooled, xr, scene, s)

    def _lean_conv(
        self,
        k: int,
        z: torch.Tensor,
        mix: Callable[[torch.Tensor], torch.Tensor],
        ring: torch.Tensor,
        s: torch.Tensor | None = None,
    ) -> torch.Tensor:
        """x⁽ᵏ⁺¹⁾ (B, N, d_h): Σ of h_k over the edges (prev, next, self) of every node.

        Args:
            z: (B, N, D) node inputs.
            mix: v (B, N, d_h) ↦ v̄ (B, N, d_h), v̄_i = Σ_c w_ic v_c (the cross terms).
            ring: (2 N,) prev and next indices.
            s: (B, N) node distances (``node_distance``), or None.
        """
        first, *rest = self.convs[k]  # a list: slicing the Sequential would build a new one
        d = z.shape[-1]
        u = z @ first.weight[:, :d].T  # (B, N, H)
        v = z @ first.weight[:, d:].T
        b, n, hd = v.shape
        c = self._node_term(k, mix(v) - v + first.bias, s)  # (B, N, H): the self edge
        if rest and self.config.activation == "leaky_relu":
            hidden = [m for m in rest[:-1] if isinstance(m, nn.Linear)]
            msg = _LeakyRingMessages.apply(u, c, ring, *(t for m in hidden for t in m.parameters()))
        else:
            ring_edges = u.index_select(1, ring).view(b, 2, n, hd) - u[:, None] + c[:, None]
            pre = torch.cat([ring_edges, c[:, None]], 1)  # (B, 3, N, H)
            if not rest:
                return pre.sum(1)
            for module in rest[:-1]:
                pre = module(pre)
            msg = pre.sum(1)
        last = rest[-1]
        return nn.functional.linear(msg, last.weight, 3 * last.bias)

    def _lean_distances(self, xr: torch.Tensor, scene: SceneGraph) -> torch.Tensor | None:
        """:meth:`node_distances` of normalised robot nodes xr (B, N_r, 2) in ``scene``: (B, N)
        robot then obstacle nodes (two-way), (B, N_r) robot nodes (one-way); None for networks
        without ``node_distance``."""
        if not self.config.node_distance:
            return None
        b = xr.shape[0]
        xo = scene.obstacles[None]
        s_r = signed_ring_distance(xr, xo, scene.obstacle_next[None])
        if not self.config.two_way:
            return s_r
        robot_next = scene.robot_next[None].expand(b, -1)
        return torch.cat([s_r, signed_ring_distance(xo.expand(b, -1, -1), xr, robot_next)], 1)

    def _lean_estimate(
        self, pooled: torch.Tensor, xr: torch.Tensor, scene: SceneGraph, s: torch.Tensor | None
    ) -> torch.Tensor:
        """:meth:`estimate` for the lean paths: node distances s, then the probe points'."""
        if not self.config.min_readout:
            return self.estimate(pooled)
        next_r = scene.robot_next[None].expand(xr.shape[0], -1)
        probes = self.probe_distances(xr, scene.obstacles[None], next_r, scene.obstacle_next[None])
        return self.estimate(pooled, torch.cat([s, probes], 1))

    def _lean_pool(self, h: torch.Tensor, score: torch.Tensor) -> torch.Tensor:
        """(B, d_h): f(Σ_i α_i x_i), α = softmax(score) over the nodes of h (B, n, d_h)."""
        alpha = torch.softmax(score, -1)
        return self.out_act((alpha[:, None] @ h).squeeze(1))


class GraphDistNetModel:
    """A trained GraphDistNet as a :class:`~gdnplan.models.DistanceModel`.

    q → node positions (:meth:`~gdnplan.graph.RobotGraph.kinematics`, float64) → d̂ in
    ``dtype`` (float32 by default) in equal chunks of at most ``chunk`` samples (default: about
    ``CHUNK_NODES`` graph nodes per pass, the nodes a configuration runs being N_r + N_o, or N_r
    for one-way networks) → ∂d̂/∂p_n by autograd on the robot node coordinates p_n (B, N, 2)
    → ∂d̂/∂q = Σ_n (∂p_n/∂q)ᵀ ∂d̂/∂p_n
    (:meth:`~gdnplan.graph.RobotGraph.pullback`, float64). ``cross="soft_knn"`` networks run
    :meth:`GraphDistNet.lean`, others the reference :meth:`GraphDistNet.forward`. The graphs of
    a scene are built once per scene object (scenes are immutable) and cached. Results are
    float64 numpy arrays. Inference runs with ``threads`` torch threads (None: the library
    default, 1; :mod:`gdnplan.models.threads`), the caller's count restored after each call.
    """

    name = "graphdistnet"

    def __init__(
        self,
        net: GraphDistNet,
        card: dict | None = None,
        chunk: int | None = None,
        dtype: torch.dtype = torch.float32,
        device: str | torch.device = "cpu",
        threads: int | None = None,
    ):
        self.net = net.to(device, dtype).eval()
        self.threads = check_threads(threads)
        self.config = net.config
        self.card = card or {}
        self.chunk = chunk
        self.dtype = dtype
        self.device = torch.device(device)
        self._scenes: weakref.WeakKeyDictionary[Scene, _SceneCache] = weakref.WeakKeyDictionary()

    def check_scene(self, scene: Scene) -> None:
        """InputError unless the weights were trained for ``scene``'s robot (models/checks.py)."""
        check_fits(self.card, scene)

    def _graphs(self, scene: Scene) -> _SceneCache:
        """The (cached) robot graph, obstacle graph and lean scene graph of ``scene``."""
        cached = self._scenes.get(scene)
        if cached is None:
            self.check_scene(scene)
            graph = robot_graph(scene.robot, self.config.max_edge)
            polys, sizes = scene_obstacles([scene])
            obstacles = obstacle_graph(
                polys, sizes, self.config.max_edge, device=self.device, dtype=self.dtype
            )
            lean = (
                self.net.scene_graph(graph, obstacles) if self.config.cross == "soft_knn" else None
            )
            cached = self._scenes[scene] = _SceneCache(graph, obstacles, lean)
        return cached

    def _estimate(
        self, graphs: _SceneCache, nodes: torch.Tensor, gen: torch.Generator | None
    ) -> torch.Tensor:
        """d̂ (B,) (m) of robot nodes (B, N_r, 2) (m)."""
        if graphs.lean is not None:
            return self.net.lean(nodes, graphs.lean)
        robot = graphs.robot.batch(nodes, device=self.device, dtype=self.dtype)
        return self.net(robot, _repeat(graphs.obstacles, len(nodes)), gen)

    def _chunks(self, n: int, graphs: _SceneCache) -> list[slice]:
        """n samples in ⌈n / chunk⌉ near-equal slices (77 → one, not 64 + 13: the fixed cost
        per pass matters at the planner's batch sizes)."""
        chunk = self.chunk
        if chunk is None:
            lean = graphs.lean
            one_way = lean is not None and lean.fixed is not None
            nodes = graphs.robot.n_nodes + (0 if one_way else graphs.obstacles.nodes.shape[1])
            chunk = max(16, CHUNK_NODES // nodes)
        edges = np.linspace(0, n, -(-n // chunk) + 1).round().astype(int)
        return [slice(a, b) for a, b in itertools.pairwise(edges)]

    def _generator(self) -> torch.Generator | None:
        return torch.Generator().manual_seed(0) if self.config.cross == "argmax" else None

    def _tensor(self, nodes: np.ndarray) -> torch.Tensor:
        return torch.as_tensor(nodes, dtype=self.dtype, device=self.device)

    def distance(self, scene: Scene, q: np.ndarray) -> np.ndarray:
        """(B,) estimated signed distances (m) of q (B, dof) or (dof,)."""
        q = scene.robot.check_q(q)
        with torch_threads(self.threads):
            graphs = self._graphs(scene)  # outside inference mode: the cache serves autograd too
            gen = self._generator()
            with torch.inference_mode():
                out = [
                    self._estimate(graphs, self._tensor(graphs.robot.positions(q[part])), gen)
                    for part in self._chunks(len(q), graphs)
                ]
                return torch.cat(out).double().cpu().numpy()

    def distance_and_grad(self, scene: Scene, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """((B,), (B, dof)): d̂ (m) and ∂d̂/∂q (m/rad)."""
        q = scene.robot.check_q(q)
        with torch_threads(self.threads):
            graphs = self._graphs(scene)
            gen = self._generator()
            ds, gs = [], []
            for part in self._chunks(len(q), graphs):
                taped = self._taped(graphs, q[part], gen)
                ds.append(taped.d.detach())
                gs.append(taped.grad(graphs.robot))
        return torch.cat(ds).double().cpu().numpy(), np.concatenate(gs)

    def distance_deferred_grad(
        self, scene: Scene, q: np.ndarray
    ) -> tuple[np.ndarray, Callable[[], np.ndarray]]:
        """d̂ (B,) (m) now and a function returning ∂d̂/∂q (B, dof) (m/rad) when called.

        The forward pass keeps its autograd graph; the backward pass runs only if the gradient
        is asked for (then once). A line search evaluates trial points it often rejects: they
        cost the forward pass alone (about half of :meth:`distance_and_grad`). Meant for
        planner-sized batches: every chunk's graph is held until the gradient is taken.
        """
        q = scene.robot.check_q(q)
        threads = self.threads
        with torch_threads(threads):
            graphs = self._graphs(scene)
            gen = self._generator()
            tapes = [self._taped(graphs, q[part], gen) for part in self._chunks(len(q), graphs)]

        @functools.cache
        def gradient() -> np.ndarray:
            with torch_threads(threads):
                return np.concatenate([t.grad(graphs.robot) for t in tapes])

        return torch.cat([t.d.detach() for t in tapes]).double().cpu().numpy(), gradient

    def _taped(self, graphs: _SceneCache, q: np.ndarray, gen: torch.Generator | None) -> _Tape:
        """The forward pass of q (B, dof) with its autograd graph on the node coordinates."""
        nodes, joints = graphs.robot.kinematics(q)
        x = self._tensor(nodes).requires_grad_(True)
        with torch.enable_grad():
            d = self._estimate(graphs, x, gen)
        return _Tape(nodes, joints, x, d)


@dataclass(frozen=True)
class _Tape:
    """A forward pass awaiting its backward pass: node positions (B, N_r, 2) (m) and their
    joints, the autograd leaf x (their tensor) and d̂ (B,)."""

    nodes: np.ndarray
    joints: np.ndarray
    x: torch.Tensor
    d: torch.Tensor

    def grad(self, robot: RobotGraph) -> np.ndarray:
        """∂d̂/∂q (B, dof): autograd to the node coordinates, then the robot's pullback."""
        (dx,) = torch.autograd.grad(self.d.sum(), self.x)
        return robot.pullback(self.nodes, self.joints, dx.double().cpu().numpy())


@dataclass(frozen=True)
class _SceneCache:
    """The graphs of one scene: robot structure, obstacle graph (1, N_o), lean constants."""

    robot: RobotGraph
    obstacles: GraphBatch
    lean: SceneGraph | None


def _repeat(graph: GraphBatch, b: int) -> GraphBatch:
    """A single graph (1, N) repeated B times (views, no copy)."""
    parts = (graph.nodes, graph.prev, graph.next, graph.mask)
    return GraphBatch(*(t.expand(b, *t.shape[1:]) for t in parts))


def load_graphdistnet(path: Path | str, threads: int | None = None) -> GraphDistNetModel:
    """A :class:`GraphDistNetModel` from ``path`` (safetensors) and the JSON card beside it,
    running inference with ``threads`` torch threads (None: the library default, 1)."""
    threads = check_threads(threads)
    path = Path(path)
    tensors, card = read_weights(path)
    config = card_config(path, card, "GraphDistNet", GraphDistNetConfig.from_dict)
    for name, value in (("layers", config.layers), ("mlp", len(config.mlp) or 1)):
        check_count(value, len(tensors), name, path)  # else a huge network before the check
    check_count(len(config.readout) or 1, len(tensors), "readout", path)
    net = build_net(path, "GraphDistNet", lambda: GraphDistNet(config), tensors)
    return GraphDistNetModel(net, card, threads=threads)
