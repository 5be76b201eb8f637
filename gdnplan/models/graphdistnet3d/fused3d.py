"""GraphDistNet-3D as one numba pass: d̂ and ∂d̂/∂nodes, tile by tile in cache.

The network of :mod:`.network` (one-way soft partners: the work per configuration is the robot
graph's alone, the obstacle features come from :meth:`GraphDistNet3D.obstacle_pass` once per
scene) in one compiled call per batch: normalisation x = (p − origin) / length, the C nearest
obstacle nodes, and per layer k the soft weights, the first linear layer per node, the sparse
cross mix, the edge MLP over the robot graph's edges (any degree) and the self edges, the last
linear layer, the attention readout and the running maximum, then the head; with the gradient,
the hand-written backward of every step to the node positions p (B, N_r, 3), tile by tile
right after the tile's forward (its activations still in cache). Per robot node i, candidate c
(obstacle node j_c, d²_ic = |x_i − x_o,j_c|²), neighbours N(i) of degree deg i:

    φ_ic = max(d²_iC − d²_ic, 1e-12),  ℓ_ic = log φ_ic − d²_ic / τ_k + s_k,j_c,  w = softmax_c ℓ,
    [u_i v_i] = z_i A_k,  c_i = Σ_c w_ic V_k,j_c − v_i + b_k,
    pre_ij = u_j − u_i + c_i (j ∈ N(i)),  pre_ii = c_i,
    h_i = W_L Σ_{j ∈ N(i) ∪ {i}} g(pre_ij) + (deg i + 1) b_L,
    y_r⁽ᵏ⁾ = σ(Σ_i α_i h_i),  α = softmax_i(a_kᵀ h_i),

z_i = x_i (k = 0) or (x_i ‖ h_i⁽ᵏ⁻¹⁾), g the edge MLP's hidden layers with σ = LeakyReLU(0.2),
V_k = z_o W_relᵀ, s_k = a_{k−1}ᵀ x_o⁽ᵏ⁾ (0 at k = 0) and the obstacle readout y_o the scene's
constants; d̂ = scale · MLP(max_k y_r⁽ᵏ⁾ ‖ y_o), whose first layer takes the constant obstacle
half into its bias. Backward, reversed: the head, the maximum (to the layer that attained it),
the readout softmax, the edge MLP (signs of the pre-activations kept as bytes), ∂u, ∂c →
∂z = [∂u, −∂c] A_kᵀ, the cross weights (∂w_ic = ∂c_i · V_k,j_c, then the softmax), ∂ℓ → ∂d²_ic
(through −d²/τ_k and log φ, whose clamp passes no gradient) → ∂x_i += 2 (x_i − x_o,j_c) ∂d²_ic,
and ∂p = ∂x / length. Products are BLAS calls on the tile (:func:`numpy.dot` in numba), the
rest loops, accumulating in the weights' dtype. The torch network computes the same function
(tests/test_graphdistnet3d_fused.py).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np
import torch

from ...graph3d import RobotGraph3D
from ..graphdistnet import fused as planar_fused
from ..graphdistnet.fused_net import conv_blocks
from ..graphdistnet.layers import LEAKY_SLOPE
from . import fused3d_kernels as _kernels
from .config import GraphDistNet3DConfig
from .network import GraphDistNet3D, ObstacleFeatures

__all__ = ["TILE_ROWS", "Packed", "pack", "refusal", "run"]

TILE_ROWS = 2048  # edge rows per tile, E + N_r per configuration (docs/decisions.md, s6-fused3d)

# the config fields this pass implements; any other field must keep its default value
IMPLEMENTED = {
    "layers",
    "hidden",
    "mlp",
    "readout",
    "cross_k",
    "tau",
    "length",
    "scale",
    "origin",
    "rim",
}


def refusal(config: GraphDistNet3DConfig) -> str | None:
    """Why the compiled pass cannot compute this network (None: it can): numba missing, an
    edge MLP or head whose hidden widths differ or are absent, or a config field it does not
    implement set to other than its default."""
    if not planar_fused.AVAILABLE:
        return "numba is not installed"
    if len(config.mlp) < 1 or len(set(config.mlp)) != 1:
        return f"mlp {config.mlp}: the pass needs hidden widths that are all equal"
    if len(config.readout) < 1 or len(set(config.readout)) != 1:
        return f"readout {config.readout}: the pass needs hidden widths that are all equal"
    for f in dataclasses.fields(config):
        if f.name not in IMPLEMENTED and getattr(config, f.name) != f.default:
            return f"{f.name} = {getattr(config, f.name)!r}: not implemented by the compiled pass"
    return None


@dataclass(frozen=True)
class Packed:
    """One scene's arrays for :func:`run`: the network and obstacle constants, the robot
    graph's edges, the candidate count C and the normalisation (of the weights' dtype)."""

    weights: _kernels.Weights
    graph: _kernels.Graph
    candidates: int
    origin: np.ndarray
    length: float
    scale: float


def _np(t: torch.Tensor, dtype: np.dtype) -> np.ndarray:
    return np.ascontiguousarray(t.detach().cpu().double().numpy().astype(dtype))


def _edges(graph: RobotGraph3D, dtype: np.dtype) -> _kernels.Graph:
    """The directed edges of the robot graph's padded neighbourhoods, grouped by source."""
    src, slot = np.nonzero(graph.nbr_mask)  # row-major: grouped by source, in slot order
    dst = graph.nbr[src, slot]
    degree = graph.nbr_mask.sum(1)
    ptr = np.concatenate([[0], np.cumsum(degree)])
    as_int = lambda a: np.ascontiguousarray(a, np.int64)  # noqa: E731
    return _kernels.Graph(as_int(src), as_int(dst), as_int(ptr), (degree + 1).astype(dtype))


@torch.no_grad()
def pack(
    net: GraphDistNet3D, feats: ObstacleFeatures, graph: RobotGraph3D, dtype: np.dtype
) -> Packed:
    """:class:`Packed` of a network (:func:`refusal` None), the obstacle features of one scene
    (batch 1) and the robot graph."""
    c = net.config
    h = c.hidden
    real = feats.mask[0]
    ax, ah, b1, wh, bh, wl, bl, v, score = [], [], [], [], [], [], [], [], []
    for k, conv in enumerate(net.convs):
        blocks = conv_blocks(conv)
        ax.append(blocks.a[:3])
        ah.append(blocks.a[3:] if k else blocks.a.new_zeros(h, blocks.a.shape[1]))
        b1.append(blocks.b1)
        wh.append(blocks.wh)
        bh.append(blocks.bh)
        wl.append(blocks.wl)
        bl.append(blocks.bl)
        v.append(feats.v[k][0][real])
        s = feats.score[k]
        score.append(torch.zeros(int(real.sum())) if s is None else s[0][real])
    head = [m for m in net.head if isinstance(m, torch.nn.Linear)]
    w0 = head[0].weight.double()
    hb0 = head[0].bias.double() + w0[:, h:] @ feats.pooled[0].double()
    hw = torch.stack([m.weight for m in head[1:-1]]) if len(head) > 2 else w0.new_zeros(0, 1, 1)
    hb = torch.stack([m.bias for m in head[1:-1]]) if len(head) > 2 else w0.new_zeros(0, 1)
    whs, wls, ahs = torch.stack(wh), torch.stack(wl), torch.stack(ah)
    arrays = _kernels.Weights(
        feats.x0[0][real],
        net.log_tau.exp(),
        torch.stack(score),
        torch.stack(v),
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
    )
    weights = _kernels.Weights(*(_np(t, dtype) for t in arrays))
    cand = min(c.cross_k + 1, len(weights.xo))
    origin = np.asarray(c.origin, dtype)
    return Packed(weights, _edges(graph, dtype), cand, origin, c.length, c.scale)


def run(packed: Packed, nodes: np.ndarray, grad: bool) -> tuple[np.ndarray, np.ndarray]:
    """d̂ (B,) (m) and, with ``grad``, ∂d̂/∂nodes (B, N_r, 3) (m/m; else an empty array) of
    robot nodes (B, N_r, 3) (m, converted to the weights' dtype)."""
    dtype = packed.origin.dtype
    x = np.ascontiguousarray((nodes - packed.origin) / dtype.type(packed.length), dtype)
    b, n, _ = x.shape
    d = np.empty(b, dtype)
    g = np.zeros((b, n, 3) if grad else (0, n, 3), dtype)
    tile = max(1, TILE_ROWS // (len(packed.graph.src) + n))
    with planar_fused._serial_blas():
        _kernels.network(
            x,
            packed.weights,
            packed.graph,
            packed.candidates,
            tile,
            dtype.type(packed.scale),
            dtype.type(LEAKY_SLOPE),
            d,
            g,
        )
    return d, g / dtype.type(packed.length)
