"""GraphDistNet-3D: message passing between a 3-D robot graph and an obstacle graph.

The planar network (:mod:`gdnplan.models.graphdistnet`, paper §IV) on 3-D coordinates, in its
planner-safe form, with neighbourhoods of any degree. One sample: robot nodes i (N_r) and
obstacle nodes (N_o) with normalised coordinates x_i⁽⁰⁾ = (p_i − origin) / scale ∈ R³, features
x_i⁽ᵏ⁾ ∈ R^{d_h}, z_i⁽⁰⁾ = x_i⁽⁰⁾, z_i⁽ᵏ⁾ = (x_i⁽⁰⁾ ‖ x_i⁽ᵏ⁾). Layer k updates every node from its
graph neighbours N(i) (masked, any degree) and itself:

    x_i⁽ᵏ⁺¹⁾ = Σ_{j ∈ N(i) ∪ {i}} h_k( z_j⁽ᵏ⁾ − z_i⁽ᵏ⁾ ‖ z̄_i⁽ᵏ⁾ − z_i⁽ᵏ⁾ ),

h_k an MLP R⁶ → R^{d_h} (k = 0), R^{2 d_h + 6} → R^{d_h} (k > 0). One-way cross edges: obstacle
nodes have z̄_i = z_i, so their features depend on the scene alone (computed once per scene,
:meth:`GraphDistNet3D.obstacle_pass`); a robot node's z̄_i is a soft partner among its c = k + 1
nearest obstacle nodes (squared distances d²_ic ascending, d²_iC the farthest of them):

    z̄_i = Σ_c w_ic z_c,   w_ic ∝ φ_ic exp(−d²_ic / τ_k + a⁽ᵏ⁾ᵀ x_c⁽ᵏ⁾),   φ_ic = d²_iC − d²_ic

(no score at k = 0; τ_k learned). φ vanishes on the C-th node, so a node entering or leaving
the candidates does so at zero weight: d̂ is deterministic and continuous in q.

Readout (paper Eq. 9–11): per graph g and layer k = 1 … K, α_i = softmax_{i∈g}(a⁽ᵏ⁾ᵀ x_i⁽ᵏ⁾),
y_g⁽ᵏ⁾ = LeakyReLU(Σ_i α_i x_i⁽ᵏ⁾), y_g = max_k y_g⁽ᵏ⁾; d̂ = scale · MLP(y_r ‖ y_o) (m).
The pooled sums average the node that decides contact with the other N_r − 1; ``min_readout``
adds a term that localises it: every robot node's estimate e_i = MLP_e(x_i⁽ᴷ⁾) (normalised
units) and their soft minimum m = −τ_m log((1/N_r) Σ_i exp(−e_i / τ_m)) (τ_m learned; between
min_i e_i and their mean, → min_i e_i as τ_m → 0), d̂ = scale · MLP(y_r ‖ y_o) + length · m.
MLP_e's last layer starts at zero, so m = 0 and d̂ is the pooled readout's at initialisation
(weights of the plain network then start the new one at the same function). m is smooth in the
node features, so d̂ stays deterministic and continuous in q.

The first linear layer of h_k is applied per node (W (z_j − z_i) = W z_j − W z_i): with
u = z W_locᵀ and v = z W_relᵀ the edge pre-activation is u_j − u_i + v̄_i − v_i + b.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import torch
from torch import nn

from ..graphdistnet.layers import LEAKY_SLOPE, _activation, masked_softmax, mlp
from .config import GraphDistNet3DConfig

PAD_DIST2 = 1e6  # squared distance (normalised units²) of padded obstacle nodes


@dataclass(frozen=True)
class ObstacleInput:
    """Obstacle graphs of a batch (or of one scene, batch 1, broadcast over the robot batch).

    Attributes:
        nodes: (S, N_o, 3) coordinates (m). mask: (S, N_o) real nodes.
        nbr: (S, N_o, D) long neighbours; nbr_mask: (S, N_o, D) real neighbours.
    """

    nodes: torch.Tensor
    mask: torch.Tensor
    nbr: torch.Tensor
    nbr_mask: torch.Tensor


@dataclass(frozen=True)
class ObstacleFeatures:
    """Scene-only quantities of the obstacle graph: normalised coordinates x0 (S, N_o, 3),
    per layer the relative projections v_k = z W_relᵀ (S, N_o, H) and scores a⁽ᵏ⁾ᵀ x⁽ᵏ⁾ (None
    at k = 0), the pooled readout y_o (S, d_h) and the node mask (S, N_o)."""

    x0: torch.Tensor
    v: list[torch.Tensor]
    score: list[torch.Tensor | None]
    pooled: torch.Tensor
    mask: torch.Tensor

    def take(self, rows: torch.Tensor) -> ObstacleFeatures:
        """The features of scenes ``rows`` (B,) (long): one row per sample of a batch."""
        pick = lambda t: None if t is None else t.index_select(0, rows)  # noqa: E731
        return ObstacleFeatures(
            pick(self.x0),
            [pick(v) for v in self.v],
            [pick(s) for s in self.score],
            pick(self.pooled),
            pick(self.mask),
        )


class GraphDistNet3D(nn.Module):
    """The network of :class:`GraphDistNet3DConfig` (module docstring)."""

    def __init__(self, config: GraphDistNet3DConfig):
        super().__init__()
        self.config = c = config
        self.convs = nn.ModuleList(
            mlp([2 * (3 if k == 0 else 3 + c.hidden), *c.mlp, c.hidden]) for k in range(c.layers)
        )
        self.attention = nn.Parameter(torch.randn(c.layers, c.hidden) / math.sqrt(c.hidden))
        self.log_tau = nn.Parameter(torch.full((c.layers,), math.log(c.tau)))
        self.head = mlp([2 * c.hidden, *c.readout, 1])
        self.out_act = _activation()
        init_weights(self)
        if c.min_readout:  # drawn after the plain network's parameters, which stay as without it
            self.node_head = mlp([c.hidden, *c.readout, 1])
            self.log_tau_min = nn.Parameter(torch.tensor(math.log(c.tau_min)))
            _he(self.node_head)
            with torch.no_grad():
                self.node_head[-1].weight.zero_()  # m = 0: d̂ starts as the pooled readout's

    def normalise(self, p: torch.Tensor) -> torch.Tensor:
        origin = torch.as_tensor(self.config.origin, dtype=p.dtype, device=p.device)
        return (p - origin) / self.config.length

    # ------------------------------------------------------------------ messages
    def messages(
        self,
        k: int,
        z: torch.Tensor,
        nbr: torch.Tensor,
        nbr_mask: torch.Tensor,
        v_bar: torch.Tensor | None,
    ) -> torch.Tensor:
        """x⁽ᵏ⁺¹⁾ (B, N, H) of nodes z (B, N, D) with neighbours nbr, nbr_mask ((B or 1), N, E)
        and cross terms v̄ = Σ_c w_c v_c (B, N, H) (None: no cross term, z̄ = z)."""
        first = self.convs[k][0]
        d = z.shape[-1]
        u = z @ first.weight[:, :d].T  # (B, N, H)
        b, n, h = u.shape
        e = nbr.shape[-1]
        flat = nbr.expand(b, -1, -1).reshape(b, n * e, 1).expand(-1, -1, h)
        u_j = torch.gather(u, 1, flat).view(b, n, e, h)
        node = first.bias if v_bar is None else v_bar - z @ first.weight[:, d:].T + first.bias
        node = node.expand(b, n, h) if v_bar is None else node
        pre = (
            torch.cat([u_j - u[:, :, None], torch.zeros_like(u[:, :, None])], 2) + node[:, :, None]
        )
        mask = torch.cat([nbr_mask.expand(b, -1, -1), nbr_mask.new_ones(b, n, 1)], 2)
        keep = mask[..., None].to(pre.dtype)
        last = self.convs[k][-1]  # Σ_e m_e (W a_e + b) = W Σ_e m_e a_e + (Σ_e m_e) b
        summed = (self.convs[k][1:-1](pre) * keep).sum(2)
        return (
            torch.addmm(last.bias, summed.flatten(0, 1), last.weight.T).view(b, n, -1)
            + (keep.sum(2) - 1) * last.bias
        )

    def pool(self, h: torch.Tensor, k: int, mask: torch.Tensor | None) -> torch.Tensor:
        """LeakyReLU(Σ_i α_i x_i⁽ᵏ⁾) (B, H), α = softmax of a⁽ᵏ⁾ᵀ x⁽ᵏ⁾ over the (masked) nodes."""
        score = h @ self.attention[k - 1]
        alpha = torch.softmax(score, -1) if mask is None else masked_softmax(score, mask)
        return self.out_act((alpha[..., None] * h).sum(1))

    # ------------------------------------------------------------------ obstacles
    def obstacle_pass(self, obs: ObstacleInput) -> ObstacleFeatures:
        """The scene-only features of obstacle graphs (module docstring)."""
        x0 = self.normalise(obs.nodes)
        keep = obs.mask[..., None].to(x0.dtype)
        h, vs, scores, pooled = None, [], [], None
        for k in range(self.config.layers):
            z = x0 if h is None else torch.cat([x0, h], -1)
            d = z.shape[-1]
            vs.append(z @ self.convs[k][0].weight[:, d:].T)
            scores.append(None if h is None else h @ self.attention[k - 1])
            h = self.messages(k, z, obs.nbr, obs.nbr_mask, None) * keep
            y = self.pool(h, k + 1, obs.mask)
            pooled = y if pooled is None else torch.maximum(pooled, y)
        return ObstacleFeatures(x0, vs, scores, pooled, obs.mask)

    # ------------------------------------------------------------------ robot
    def candidates(
        self, xr: torch.Tensor, feats: ObstacleFeatures
    ) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
        """The C = k + 1 nearest obstacle nodes of every robot node: indices (B, N_r, C),
        log φ (B, N_r, C) and d² (B, N_r, C), ascending; differentiable in xr (B, N_r, 3)."""
        xo, mask = feats.x0, feats.mask
        b = xr.shape[0]
        c = min(self.config.cross_k + 1, xo.shape[1])
        with torch.no_grad():
            d2 = torch.cdist(xr, xo.expand(b, -1, -1)).square()
            d2 = d2.masked_fill(~mask[:, None].expand(b, -1, -1), PAD_DIST2)
            idx = torch.topk(d2, c, dim=-1, largest=False).indices
        near = _gather_nodes(xo, idx)  # (B, N_r, C, 3)
        d2 = (xr[:, :, None] - near).square().sum(-1)
        d2 = torch.where(_gather_rows(mask, idx), d2, torch.full_like(d2, PAD_DIST2))
        log_phi = (d2[..., -1:] - d2).clamp_min(1e-12).log()
        return idx, log_phi, d2

    def forward(
        self,
        robot_nodes: torch.Tensor,
        robot_nbr: torch.Tensor,
        robot_nbr_mask: torch.Tensor,
        feats: ObstacleFeatures,
    ) -> torch.Tensor:
        """d̂ (B,) (m) of robot nodes (B, N_r, 3) (m) with neighbourhoods (N_r, E) among the
        obstacle features of :meth:`obstacle_pass` (batch B, or 1 for one scene)."""
        xr = self.normalise(robot_nodes)
        idx, log_phi, d2 = self.candidates(xr, feats)
        b = idx.shape[0]
        h, pooled = None, None
        for k in range(self.config.layers):
            z = xr if h is None else torch.cat([xr, h], -1)
            logits = log_phi - d2 / self.log_tau[k].exp()
            if k > 0:
                logits = logits + _gather_rows(feats.score[k], idx)
            w = torch.softmax(logits, -1)
            v_c = _gather_nodes(feats.v[k], idx)  # (B, N_r, C, H)
            v_bar = (w[:, :, None] @ v_c).squeeze(2)
            h = self.messages(k, z, robot_nbr[None], robot_nbr_mask[None], v_bar)
            y = self.pool(h, k + 1, None)
            pooled = y if pooled is None else torch.maximum(pooled, y)
        both = torch.cat([pooled, feats.pooled.expand(b, -1)], -1)
        d = self.head(both).squeeze(-1) * self.config.scale
        if not self.config.min_readout:
            return d
        return d + self.soft_min(self.node_head(h).squeeze(-1)) * self.config.length

    def soft_min(self, e: torch.Tensor) -> torch.Tensor:
        """m (B,) = −τ_m log((1/N) Σ_i exp(−e_i / τ_m)) of node estimates e (B, N)."""
        tau = self.log_tau_min.exp()
        return -tau * (torch.logsumexp(-e / tau, -1) - math.log(e.shape[-1]))


def init_weights(net: GraphDistNet3D, degree: int = 3) -> None:
    """Initialise ``net`` so that features keep their size through the layers: He weights for
    LeakyReLU(0.2) and zero biases in every linear layer (PyTorch's default shrinks the
    variance threefold per layer and its biases then swamp the input: d̂ hardly depends on q),
    the last layer of each h_k divided by the degree + 1 terms a message sums, and the head's
    last layer by 10 (d̂ starts near a constant, but a constant whose gradients reach every
    layer). (``min_readout``'s node estimates are drawn afterwards, their last layer zero.)"""
    _he(net)
    with torch.no_grad():
        for conv in net.convs:
            conv[-1].weight /= degree + 1
        net.head[-1].weight /= 10


def _he(module: nn.Module) -> None:
    """He weights for LeakyReLU(0.2) and zero biases in every linear layer of ``module``."""
    for m in module.modules():
        if isinstance(m, nn.Linear):
            nn.init.kaiming_normal_(m.weight, a=LEAKY_SLOPE, nonlinearity="leaky_relu")
            nn.init.zeros_(m.bias)


def _gather_nodes(x: torch.Tensor, idx: torch.Tensor) -> torch.Tensor:
    """(B, N, C, F) rows of x ((B or 1), M, F) at idx (B, N, C)."""
    b, n, c = idx.shape
    f = x.shape[-1]
    flat = idx.reshape(b, n * c, 1).expand(-1, -1, f)
    return torch.gather(x.expand(b, -1, -1), 1, flat).view(b, n, c, f)


def _gather_rows(x: torch.Tensor, idx: torch.Tensor) -> torch.Tensor:
    """(B, N, C) entries of x ((B or 1), M) at idx (B, N, C)."""
    b, n, c = idx.shape
    return torch.gather(x.expand(b, -1), 1, idx.reshape(b, n * c)).view(b, n, c)
