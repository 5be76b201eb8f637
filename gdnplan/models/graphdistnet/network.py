"""The GraphDistNet module: parameters and the padded reference forward pass (paper §IV,
the package docstring); the lean inference path comes from :class:`LeanInference`."""

from __future__ import annotations

import math
from dataclasses import dataclass

import torch
from torch import nn

from ...graph import GraphBatch
from .config import GraphDistNetConfig
from .geometry import PAD_DIST2, nearest_candidates, signed_ring_distance
from .layers import _activation, masked_softmax, mlp
from .lean import LeanInference


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


class GraphDistNet(LeanInference, nn.Module):
    """The network of :class:`GraphDistNetConfig`; ``forward(robot, obstacles) -> d̂ (B,)`` (m)."""

    def __init__(self, config: GraphDistNetConfig):
        super().__init__()
        self.config = config
        c = config
        self.convs = nn.ModuleList()
        for k in range(c.layers):
            d_in = 2 if k == 0 else 2 + c.hidden  # size of z_i
            self.convs.append(mlp([2 * d_in, *c.mlp, c.hidden]))
        self.attention = nn.Parameter(torch.randn(c.layers, c.hidden) / math.sqrt(c.hidden))
        self.log_tau = nn.Parameter(torch.full((c.layers,), math.log(c.tau)))
        self.head = mlp([2 * c.hidden + int(c.min_readout), *c.readout, 1])
        self.out_act = _activation()
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
        """(B, N) paper partners: at k = 0 a random node of the other graph (one per graph,
        the partner of all its nodes), else the argmax of a⁽ᵏ⁾ᵀ x⁽ᵏ⁾ in the other graph."""
        b, n = g.mask.shape
        n_r = g.n_robot
        valid_r = g.mask[:, :n_r].sum(1, keepdim=True)  # valid nodes come first in each graph
        valid_o = g.mask[:, n_r:].sum(1, keepdim=True)
        is_robot = torch.arange(n, device=g.mask.device) < n_r
        if h is None:  # one draw per graph (the paper)
            u = torch.rand(b, 2, generator=generator, device=g.mask.device)
            u_o, u_r = u[:, :1], u[:, 1:]
            pick_o = n_r + (u_o * valid_o).long().clamp_max(valid_o - 1)
            pick_r = (u_r * valid_r).long().clamp_max(valid_r - 1)
            return torch.where(is_robot, pick_o, pick_r).expand(b, n)
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
