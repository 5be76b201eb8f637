"""The whole GraphDistNet as one numba pass: d̂ and ∂d̂/∂nodes, tile by tile in cache.

For soft-kNN networks (:func:`serves`: one-way or two-way; node distances, their soft-minimum
readout, probe points and band one-way, by :mod:`.fused_net_distances`) this module runs the
network in one compiled call per batch: normalisation x = (p − origin) / scale, the C nearest
partner nodes, and per layer k the soft weights, the first linear layer per node, the sparse cross
mix, the edge MLP, the last linear layer, the attention readout and the running maximum, then
the head; with the gradient, the hand-written backward of every step to the robot node
positions p (B, N_r, 2), tile by tile right after the tile's forward (its activations still in
cache). A configuration's rows are its N_r robot nodes (one-way, ``two_way=False``: package
docstring, "One-way") or the union of its robot and N_o obstacle nodes (two-way: the obstacle
graph's features depend on the configuration through its cross edges). Per row i, candidate c
(node j_c of the other graph, d²_ic = |x_i − x_j_c|²):

    φ_ic = max(d²_iC − d²_ic, 1e-12),  ℓ_ic = log φ_ic − d²_ic / τ_k + s_k,j_c,  w = softmax_c ℓ,
    [u_i v_i] = z_i A_k,  c_i = Σ_c w_ic V_k,j_c − v_i + b_k,  pre = (u_j − u_i + c_i, c_i),
    h_i = W_L Σ_e g(pre_e) + 3 b_L,  y_g = σ(Σ_{i∈g} α_i h_i),  α = softmax_{i∈g}(a_kᵀ h_i),

z_i = x_i (k = 0) or (x_i ‖ h_i⁽ᵏ⁻¹⁾), g the hidden layers with σ = LeakyReLU(0.2) (the ring
messages of :mod:`.fused`). Two-way: V_k,j = v_j and s_k,j = a_{k−1}ᵀ h_j⁽ᵏ⁻¹⁾ (0 at k = 0) are
the partner row's own, d̂ = scale · MLP(max_k y_r ‖ max_k y_o). One-way: V_k, s_k and the
obstacle readout y_o⁽ᵏ⁾ are the scene's constants (:class:`~.lean.ObstacleFeatures`) and the
head's first layer takes the constant obstacle half into its bias. When the other graph has
fewer than C nodes the missing candidates get weight 0. Backward, reversed: the head, the
maximum (to the layer that attained it), the readout softmax, the edge MLP (signs of the
pre-activations kept as bytes), ∂u, ∂c → ∂z = [∂u, −∂c] A_kᵀ, the cross weights (∂w_ic =
∂c_i · V_k,j_c, then the softmax; two-way also ∂v_j_c += w_ic ∂c_i and ∂h_j_c⁽ᵏ⁻¹⁾ += ∂ℓ_ic
a_{k−1}), ∂ℓ → ∂d²_ic (through −d²/τ_k and log φ, whose clamp passes no gradient) → the
robot node of the pair += 2 (x_robot − x_obstacle) ∂d²_ic, and ∂p = ∂x / scale (obstacle
nodes are constants). Distance-aware one-way networks add the node distance s_i w_k to c_i
(so ∂s_i += ∂c_i · w_k) and, with ``min_readout``, the soft minimum m of the node and probe
distances to the head (:mod:`.fused_net_distances`); ∂s then goes back to the nodes through
the exact ring-distance gradient. Products are BLAS calls on the tile (:func:`numpy.dot` in
numba), the rest loops. The torch reference computes the same function
(tests/test_graphdistnet_fused_net.py).
"""

from __future__ import annotations

import itertools
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
import torch

from . import fused
from . import fused_net_kernels as _kernels
from .config import GraphDistNetConfig
from .layers import LEAKY_SLOPE

__all__ = ["TILE_ROWS", "PackedNetwork", "pack", "run", "serves"]

TILE_ROWS = 2048  # edge rows per tile, 3 n per configuration (docs/decisions.md, s7-kernel)


def serves(config: GraphDistNetConfig) -> bool:
    """Whether the whole-network kernel computes this network: soft-kNN, one-way or two-way
    (node distances, with their soft-minimum readout, probe points and band: one-way only),
    edge MLP hidden widths all equal (:func:`.fused.supports`) and readout widths all equal
    (at least one hidden layer in the head)."""
    return (
        fused.supports(config.mlp)
        and config.cross == "soft_knn"
        and config.mlp[0] == config.hidden
        and not (config.node_distance and config.two_way)
        and len(config.readout) >= 1
        and len(set(config.readout)) == 1
    )


@dataclass(frozen=True)
class PackedNetwork:
    """The network and one scene's constants for the kernel: ``net`` a
    :class:`~.fused_net_kernels.Net` of contiguous arrays of the model's dtype, ``origin``
    (2,) and ``scale`` of the normalisation, C = ``candidates`` per node."""

    net: _kernels.Net
    origin: np.ndarray
    scale: float
    candidates: int


def _np(t: torch.Tensor, dtype: np.dtype) -> np.ndarray:
    return np.ascontiguousarray(t.detach().cpu().double().numpy().astype(dtype))


class ConvBlocks(NamedTuple):
    """One message layer h_k as the compiled passes use it: ``a`` (d, 2P) with [u v] = z a
    for z = (x ‖ h) of d features, ``b1`` (P,) its first bias, ``wh`` (L, P, P) / ``bh`` (L, P)
    the hidden layers (L may be 0), ``wl`` / ``bl`` the last layer."""

    a: torch.Tensor
    b1: torch.Tensor
    wh: torch.Tensor
    bh: torch.Tensor
    wl: torch.Tensor
    bl: torch.Tensor


def conv_blocks(conv) -> ConvBlocks:
    """:class:`ConvBlocks` of a layer ``conv`` (Linear, activations, …, Linear) whose first
    Linear sees (z_j − z_i ‖ z̄_i − z_i) of z = (x ‖ h): the coordinates are a's first rows."""
    first, *rest = conv
    w = first.weight.double()  # (P, 2d)
    d = w.shape[1] // 2
    a = torch.cat([w[:, :d].T, w[:, d:].T], 1)
    hidden = [m for m in rest[:-1] if isinstance(m, torch.nn.Linear)]
    p = w.shape[0]
    wh = torch.stack([m.weight for m in hidden]) if hidden else w.new_zeros(0, p, p)
    bh = torch.stack([m.bias for m in hidden]) if hidden else w.new_zeros(0, p)
    return ConvBlocks(a, first.bias, wh, bh, rest[-1].weight, rest[-1].bias)


@torch.no_grad()
def pack(net, scene, dtype: np.dtype) -> PackedNetwork:
    """:class:`PackedNetwork` of a :class:`~.network.GraphDistNet` ``net`` (:func:`serves`)
    and its :class:`~.lean.SceneGraph` ``scene`` (one-way: with ``fixed``)."""
    c, fixed = net.config, scene.fixed
    h = c.hidden
    ax, ah, b1, wh, bh, wl, bl = [], [], [], [], [], [], []
    for k, conv in enumerate(net.convs):
        blocks = conv_blocks(conv)
        ax.append(blocks.a[:2])
        ah.append(blocks.a[2:] if k else blocks.a.new_zeros(h, 2 * h))
        b1.append(blocks.b1)
        wh.append(blocks.wh)
        bh.append(blocks.bh)
        wl.append(blocks.wl)
        bl.append(3 * blocks.bl.double())  # the three edges of a ring node sum their biases
    head = [m for m in net.head if isinstance(m, torch.nn.Linear)]
    w0, hb0 = head[0].weight.double(), head[0].bias.double()
    n_r, n_o = len(scene.robot_ring) // 2, len(scene.obstacles)
    if fixed is None:  # two-way: both graphs' readouts per configuration, partners per row
        score, v, ring = w0.new_zeros(c.layers, 0), w0.new_zeros(c.layers, 0, h), scene.ring
        cand = min(c.cross_k + 1, max(n_r, n_o))
    else:  # one-way: max_k y_o⁽ᵏ⁾ is a constant of the scene, folded into the head's bias
        hb0 = hb0 + w0[:, h : 2 * h] @ fixed.readout.double().amax(0)
        score, v, ring = fixed.score, fixed.v, scene.robot_ring
        cand = min(c.cross_k + 1, n_o)
    hm = w0[:, 2 * h] if c.min_readout else w0.new_zeros(0)  # the soft minimum's column
    w0 = w0 if fixed is None else w0[:, :h]
    din = net.distance_in.double() if c.node_distance else w0.new_zeros(c.layers, 0)
    hw = torch.stack([m.weight for m in head[1:-1]]) if len(head) > 2 else w0.new_zeros(0, 1, 1)
    hb = torch.stack([m.bias for m in head[1:-1]]) if len(head) > 2 else w0.new_zeros(0, 1)
    whs, wls, ahs = torch.stack(wh), torch.stack(wl), torch.stack(ah)
    ring = np.ascontiguousarray(ring.view(2, -1).cpu().numpy().astype(np.int64))
    arrays = _kernels.Net(
        xo=_np(scene.obstacles, dtype),
        ring=ring,
        tau=net.log_tau.exp(),
        score=score,
        v=v,
        ax=torch.stack(ax),
        ah=ahs,
        aht=ahs.transpose(1, 2),
        b1=torch.stack(b1),
        wht=whs.transpose(2, 3),
        wh=whs,
        bh=torch.stack(bh),
        wlt=wls.transpose(1, 2),
        wl=wls,
        bl3=torch.stack(bl),
        att=net.attention,
        h0t=w0.T,
        h0=w0,
        hb0=hb0,
        hwt=hw.transpose(1, 2),
        hw=hw,
        hb=hb,
        wlast=head[-1].weight[0],
        blast=head[-1].bias,
        scale=np.dtype(dtype).type(c.scale),
        slope=np.dtype(dtype).type(LEAKY_SLOPE),
        onext=np.ascontiguousarray(scene.obstacle_next.cpu().numpy().astype(np.int64)),
        probe=c.probe_split,
        din=din,
        hm=hm,
        tau_min=np.dtype(dtype).type(net.log_tau_min.exp().item() if c.min_readout else 1.0),
        band=np.dtype(dtype).type(c.correction_band or 0.0),
    )
    tensors = {k: _np(t, dtype) for k, t in arrays._asdict().items() if isinstance(t, torch.Tensor)}
    return PackedNetwork(arrays._replace(**tensors), np.asarray(c.origin, dtype), c.scale, cand)


def run(
    weights: PackedNetwork, nodes: np.ndarray, grad: bool, threads: int = 1
) -> tuple[np.ndarray, np.ndarray]:
    """d̂ (B,) (m) and, with ``grad``, ∂d̂/∂nodes (B, N_r, 2) (else an empty array) of robot
    nodes (B, N_r, 2) (m, converted to the weights' dtype), on up to ``threads`` threads: the
    batch split on tile boundaries (the kernel releases the GIL; every tile's result is the
    same whichever thread runs it)."""
    dtype = weights.origin.dtype
    x = np.ascontiguousarray((nodes - weights.origin) / dtype.type(weights.scale), dtype)
    b, n_r, _ = x.shape
    d = np.empty(b, dtype)
    g = np.zeros((b, n_r, 2) if grad else (0, n_r, 2), dtype)
    tile = max(1, TILE_ROWS // (3 * weights.net.ring.shape[1]))
    tiles = -(-b // tile)
    edges = [tile * (tiles * i // threads) for i in range(threads)] + [b]
    parts = [slice(lo, hi) for lo, hi in itertools.pairwise(dict.fromkeys(edges)) if hi > lo]

    def part(s: slice) -> None:
        _kernels.network(x[s], weights.net, weights.candidates, d[s], g[s], tile)

    with fused._serial_blas():
        if len(parts) <= 1:
            for s in parts:
                part(s)
        else:
            with ThreadPoolExecutor(len(parts)) as pool:
                list(pool.map(part, parts))
    return d, g / dtype.type(weights.scale)
