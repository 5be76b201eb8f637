"""The whole one-way GraphDistNet as one numba pass: d̂ and ∂d̂/∂nodes, tile by tile in cache.

For ``two_way=False`` networks without node distances (:func:`serves`) the work per
configuration is the robot graph's alone (package docstring, "One-way"). This module runs all
of it in one compiled call per batch: normalisation x = (p − origin) / scale, the C nearest
obstacle nodes, and per layer k the soft weights, the first linear layer per node, the sparse
cross mix, the edge MLP, the last linear layer, the attention readout and the running maximum,
then the head; with the gradient, the hand-written backward of every step to the node
positions p (B, N_r, 2), tile by tile right after the tile's forward (its activations still in
cache). Per robot node i, candidate c (obstacle node j_c, d²_ic = |x_i − x_o,j_c|²):

    φ_ic = max(d²_iC − d²_ic, 1e-12),  ℓ_ic = log φ_ic − d²_ic / τ_k + s_k,j_c,  w = softmax_c ℓ,
    [u_i v_i] = z_i A_k,  c_i = Σ_c w_ic V_k,j_c − v_i + b_k,  pre = (u_j − u_i + c_i, c_i),
    h_i = W_L Σ_e g(pre_e) + 3 b_L,  y_r = σ(Σ_i α_i h_i),  α = softmax_i(a_kᵀ h_i),

z_i = x_i (k = 0) or (x_i ‖ h_i⁽ᵏ⁻¹⁾), g the hidden layers with σ = LeakyReLU(0.2) (the ring
messages of :mod:`.fused`), V_k, s_k and the obstacle readout y_o⁽ᵏ⁾ the scene's constants
(:class:`~.lean.ObstacleFeatures`); y_r = max_k y_r⁽ᵏ⁾, d̂ = scale · MLP(y_r ‖ max_k y_o⁽ᵏ⁾),
whose first layer takes the constant obstacle half into its bias. Backward, reversed: the
head, the maximum (to the layer that attained it), the readout softmax, the edge MLP (signs
of the pre-activations kept as bytes), ∂u, ∂c → ∂z = [∂u, −∂c] A_kᵀ, the cross weights
(∂w_ic = ∂c_i · V_k,j_c, then the softmax), ∂ℓ → ∂d²_ic (through −d²/τ_k and log φ,
whose clamp passes no gradient) → ∂x_i += 2 (x_i − x_o,j_c) ∂d²_ic, and ∂p = ∂x / scale.
Products are BLAS calls on the tile (:func:`numpy.dot` in numba), the rest loops.
The torch reference computes the same function (tests/test_graphdistnet_fused_net.py).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import torch

from . import fused
from . import fused_net_kernels as _kernels
from .config import GraphDistNetConfig
from .layers import LEAKY_SLOPE

__all__ = ["OneWayWeights", "pack", "run", "serves"]


def serves(config: GraphDistNetConfig) -> bool:
    """Whether the whole-network kernel computes this network: soft-kNN, one-way, no node
    distances, edge MLP hidden widths all equal (:func:`.fused.supports`) and readout widths
    all equal (at least one hidden layer in the head)."""
    return (
        fused.supports(config.mlp)
        and config.cross == "soft_knn"
        and not config.two_way
        and not config.node_distance
        and len(config.readout) >= 1
        and len(set(config.readout)) == 1
    )


@dataclass(frozen=True)
class OneWayWeights:
    """The network and one scene's constants as contiguous arrays of the model's dtype
    (K layers, H = d_h, L hidden layers of the edge MLP, R readout width, M obstacle nodes):
    ``net`` holds, in the kernel's argument order, xo (M, 2), ring (2, N_r), tau (K,), score
    (K, M), v (K, M, H), ax (K, 2, 2H), ah (K, H, 2H), aht (K, 2H, H), b1 (K, H), wht / wh
    (K, L, H, H) (transposed / not), bh (K, L, H), wlt / wl (K, H, H), bl3 (K, H) = 3 b_L,
    att (K, H), h0t (H, R), h0 (R, H), hb0 (R,), hwt / hw (Lr, R, R), hb (Lr, R), wlast (R,),
    blast (1,); ``origin`` (2,), ``scale``, C = ``candidates``."""

    net: tuple[np.ndarray, ...]
    origin: np.ndarray
    scale: float
    candidates: int


def _np(t: torch.Tensor, dtype: np.dtype) -> np.ndarray:
    return np.ascontiguousarray(t.detach().cpu().double().numpy().astype(dtype))


@torch.no_grad()
def pack(net, scene, dtype: np.dtype) -> OneWayWeights:
    """:class:`OneWayWeights` of a :class:`~.network.GraphDistNet` ``net`` (:func:`serves`)
    and its :class:`~.lean.SceneGraph` ``scene`` (with ``fixed``)."""
    c, fixed = net.config, scene.fixed
    h = c.hidden
    ax, ah, b1, wh, bh, wl, bl = [], [], [], [], [], [], []
    for k, conv in enumerate(net.convs):
        first, *rest = conv
        w = first.weight.double()  # (H, 2d), z = (x ‖ h)
        d = w.shape[1] // 2
        a = torch.cat([w[:, :d].T, w[:, d:].T], 1)  # (d, 2H): [u v] = z a
        ax.append(a[:2])
        ah.append(a[2:] if k else a.new_zeros(h, 2 * h))
        b1.append(first.bias)
        hidden = [m for m in rest[:-1] if isinstance(m, torch.nn.Linear)]
        wh.append(torch.stack([m.weight for m in hidden]))
        bh.append(torch.stack([m.bias for m in hidden]))
        wl.append(rest[-1].weight)
        bl.append(3 * rest[-1].bias.double())
    head = [m for m in net.head if isinstance(m, torch.nn.Linear)]
    w0 = head[0].weight.double()
    obstacle_half = fixed.readout.double().amax(0)  # max_k y_o⁽ᵏ⁾, a constant of the scene
    hb0 = head[0].bias.double() + w0[:, h:] @ obstacle_half
    hw = torch.stack([m.weight for m in head[1:-1]]) if len(head) > 2 else w0.new_zeros(0, 1, 1)
    hb = torch.stack([m.bias for m in head[1:-1]]) if len(head) > 2 else w0.new_zeros(0, 1)
    whs, wls, ahs = torch.stack(wh), torch.stack(wl), torch.stack(ah)
    n_r = len(scene.robot_ring) // 2
    arrays = [
        net.log_tau.exp(),
        fixed.score,
        fixed.v,
        torch.stack(ax),
        ahs,
        ahs.transpose(1, 2),
        torch.stack(b1),
        whs.transpose(2, 3),
        whs,
        torch.stack(bh),
        wls.transpose(1, 2),
        wls,
        torch.stack(bl),
        net.attention,
        w0[:, :h].T,
        w0[:, :h],
        hb0,
        hw.transpose(1, 2),
        hw,
        hb,
        head[-1].weight[0],
        head[-1].bias,
    ]
    ring = np.ascontiguousarray(scene.robot_ring.view(2, n_r).cpu().numpy().astype(np.int64))
    packed = [_np(scene.obstacles, dtype), ring, *(_np(t, dtype) for t in arrays)]
    cand = min(c.cross_k + 1, len(scene.obstacles))
    return OneWayWeights(tuple(packed), np.asarray(c.origin, dtype), float(c.scale), cand)


def run(weights: OneWayWeights, nodes: np.ndarray, grad: bool) -> tuple[np.ndarray, np.ndarray]:
    """d̂ (B,) (m) and, with ``grad``, ∂d̂/∂nodes (B, N_r, 2) (else an empty array) of robot
    nodes (B, N_r, 2) (m, converted to the weights' dtype)."""
    dtype = weights.origin.dtype
    x = np.ascontiguousarray((nodes - weights.origin) / dtype.type(weights.scale), dtype)
    b, n, _ = x.shape
    d = np.empty(b, dtype)
    g = np.zeros((b, n, 2) if grad else (0, n, 2), dtype)
    tile = max(1, fused.TILE_ROWS // (3 * n))
    scale = dtype.type(weights.scale)
    with fused._serial_blas():
        _kernels.network(
            x, *weights.net, weights.candidates, d, g, scale, dtype.type(LEAKY_SLOPE), tile
        )
    return d, g / scale
