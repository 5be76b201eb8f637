"""The lean inference path of GraphDistNet: one scene's constants (:class:`SceneGraph`) and
the unpadded forward pass (:class:`LeanInference`, mixed into :class:`GraphDistNet`)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import torch
from torch import nn

from ...graph import GraphBatch, RobotGraph
from .fused import FusedRingMessages, SparseMix
from .geometry import _pairwise_d2, nearest_candidates, nearest_obstacle_nodes, signed_ring_distance
from .layers import _LeakyRingMessages


def _softmax_small(logits: torch.Tensor) -> torch.Tensor:
    """Softmax over a short last dimension (the C candidates): exp(l − max l) / Σ exp(l − max l).

    The same function as :func:`torch.softmax`, written out because so few candidates make the
    library call's overhead dominate on CPU (docs/decisions.md#lean-path); the shift max l is a
    constant to autograd (the softmax does not depend on it).
    """
    e = (logits - logits.detach().amax(-1, keepdim=True)).exp()
    return e / e.sum(-1, keepdim=True)


def _cross_mix(idx: torch.Tensor, w: torch.Tensor, n_r: int) -> tuple[torch.Tensor, torch.Tensor]:
    """Dense cross weights: M_ro (B, N_r, N_o) and M_or (B, N_o, N_r), (M)_ij = Σ_{c: j_c = j} w_ic.

    Σ_c w_ic v_{j_c} is then row i of M_ro v_o (robot nodes i) or M_or v_r (obstacle nodes):
    a batched matrix product instead of a (B, N, C, d_h) gather (docs/decisions.md#lean-path).

    Args:
        idx: (B, N, C) union indices of the candidates (robot nodes first); w: (B, N, C).
    """
    b, n, _ = idx.shape
    n_o = n - n_r
    m_ro = w.new_zeros(b, n_r, n_o).scatter_add_(-1, idx[:, :n_r] - n_r, w[:, :n_r])
    m_or = w.new_zeros(b, n_o, n_r).scatter_add_(-1, idx[:, n_r:], w[:, n_r:])
    return m_ro, m_or


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


class LeanInference:
    """The lean inference path of :class:`GraphDistNet` (``cross="soft_knn"``), mixed into it.

    The function of :meth:`GraphDistNet.forward` for one scene without padding (package
    docstring, "Inference"). The methods use the network's parameters (``convs``,
    ``attention``, ``log_tau``, ``out_act``, ``distance_in``) and its ``_node_term``,
    ``estimate`` and ``probe_distances``.
    """

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

    def lean(self, nodes: torch.Tensor, scene: SceneGraph, fused: bool = False) -> torch.Tensor:
        """d̂ (B,) (m) of robot nodes (B, N_r, 2) (m) among one scene's obstacles; ``fused``:
        the ring messages by :class:`~.fused.FusedRingMessages` (on CPU), else by
        :class:`~.layers._LeakyRingMessages` (the same function).

        The function of :meth:`forward` for ``cross="soft_knn"`` without padding, reorganised
        for inference: ring neighbours are gathered with one index shared by the batch, the
        cross terms Σ_c w_ic v_c are two dense products (:func:`_cross_mix`), a⁽ᵏ⁾ᵀ x⁽ᵏ⁾ is
        computed once for the readout and the next layer's partners, and the last linear layer
        (W, b) of h_k is applied once per node to the sum of the three edges' activations a_e:
        Σ_e (W a_e + b) = W Σ_e a_e + 3 b. One-way networks run :meth:`lean_one_way`.
        """
        if scene.fixed is not None:
            return self.lean_one_way(nodes, scene, fused)
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

            h = self._lean_conv(k, z, mix, scene.ring, s, fused)
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

    def lean_one_way(
        self, nodes: torch.Tensor, scene: SceneGraph, fused: bool = False
    ) -> torch.Tensor:
        """:meth:`lean` for ``two_way=False``: only the robot graph runs per configuration;
        partner terms, partner scores and the obstacle readout come from ``scene.fixed``
        (``fused``: the cross terms by :class:`~.fused.SparseMix` as well)."""
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
            if fused:  # Σ_c w_ic v_{j_c} over the C candidates only

                def mix(v: torch.Tensor, w=w, v_o=fixed.v[k]) -> torch.Tensor:
                    return SparseMix.apply(w, idx, v_o)

            else:
                m_ro = w.new_zeros(*idx.shape[:2], n_o).scatter_add_(-1, idx, w)  # (B, N_r, N_o)

                def mix(v: torch.Tensor, m_ro=m_ro, v_o=fixed.v[k]) -> torch.Tensor:
                    return m_ro @ v_o

            z = xr if h is None else torch.cat([xr, h], -1)
            h = self._lean_conv(k, z, mix, scene.robot_ring, s, fused)
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
        fused: bool = False,
    ) -> torch.Tensor:
        """x⁽ᵏ⁺¹⁾ (B, N, d_h): Σ of h_k over the edges (prev, next, self) of every node.

        Args:
            z: (B, N, D) node inputs.
            mix: v (B, N, d_h) ↦ v̄ (B, N, d_h), v̄_i = Σ_c w_ic v_c (the cross terms).
            ring: (2 N,) prev and next indices.
            s: (B, N) node distances (``node_distance``), or None.
            fused: the ring messages by the fused kernel (:meth:`lean`).
        """
        first, *rest = self.convs[k]  # a list: slicing the Sequential would build a new one
        d = z.shape[-1]
        u = z @ first.weight[:, :d].T  # (B, N, H)
        v = z @ first.weight[:, d:].T
        b, n, hd = v.shape
        c = self._node_term(k, mix(v) - v + first.bias, s)  # (B, N, H): the self edge
        if not rest:
            ring_edges = u.index_select(1, ring).view(b, 2, n, hd) - u[:, None] + c[:, None]
            return torch.cat([ring_edges, c[:, None]], 1).sum(1)  # (B, 3, N, H) summed
        hidden = [m for m in rest[:-1] if isinstance(m, nn.Linear)]
        messages = FusedRingMessages if fused else _LeakyRingMessages
        msg = messages.apply(u, c, ring, *(t for m in hidden for t in m.parameters()))
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
