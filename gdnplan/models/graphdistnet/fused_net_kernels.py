"""The compiled kernels of :mod:`.fused_net` (numba; the math is in that module's docstring).

:func:`network` loops over tiles of configurations; per tile :func:`_forward_tile` runs the
network (its readout and head: :mod:`.fused_net_readout`) and keeps what the backward needs
in a :class:`State` (candidates, soft weights, partner terms, signs of the pre-activations,
features, readout weights), and with the
gradient :func:`.fused_net_backward._backward_tile` runs the reverse pass at once. The
network's arrays travel as one :class:`Net`. Shapes: T configurations per tile, n union rows
per configuration (the N_r robot nodes, then for two-way networks the N_o obstacle nodes),
C candidates, K layers, H features, P = H (one-way) or 2 H (two-way) pooled features, L
hidden layers of the edge MLP, R readout width, Q distance points per configuration (0
without node distances; :mod:`.fused_net_distances`).
"""

from __future__ import annotations

from collections import namedtuple

import numpy as np

from .fused import AVAILABLE
from .fused_search import NO_WEIGHT
from .geometry import PAD_DIST2

Net = namedtuple(
    "Net",
    "xo ring tau score v ax ah aht b1 wht wh bh wlt wl bl3 att h0t h0 hb0 hwt hw hb wlast blast "
    "scale slope onext probe din hm tau_min band",
)
Net.__doc__ = """The network and one scene's constants (:func:`.fused_net.pack`): xo (M, 2)
obstacle nodes, ring (2, n) prev/next union rows, tau (K,), one-way partner terms score
(K, M) and v (K, M, H) (two-way: (K, 0), (K, 0, H)), [u v] = z A_k as ax (K, 2, 2H), ah
(K, H, 2H), aht = ahᵀ, b1 (K, H), edge MLP wht / wh (K, L, H, H) (transposed / not), bh
(K, L, H), last layer wlt / wl (K, H, H), bl3 (K, H) = 3 b_L, att (K, H), head h0t (P, R), h0
(R, P), hb0 (R,), hwt / hw (Lr, R, R), hb (Lr, R), wlast (R,), blast (1,), scale and the
LeakyReLU slope (scalars of the dtype); distance-aware one-way networks: onext (M,) the
obstacle rings' successors, probe = ``probe_split`` (int), din (K, H) the node distances'
weights w_k (K, 0 without), hm (R,) the head's column of the soft minimum (0 without
``min_readout``), tau_min and band β (0: none) scalars."""

State = namedtuple("State", "xu idx near lphi w v h mask logit alpha ypos src hmask s ds sw m y")
State.__doc__ = """Per tile: xu (T, n, 2) union coordinates, idx / near / lphi (T, n, C)
candidates (partner rows, d², log φ), w (K, T, n, C) soft weights, v (K, T n, H) two-way
partner terms (one-way: no rows), h (K, T n, H) features, mask (K, L + 1, 3 T n, H) signs of
the edge pre-activations, logit / alpha (K, T, n) readout scores and weights, ypos (K, T, P)
signs of the readouts, src (T, P) the layer of each pooled maximum, hmask (Lr + 1, T, R)
signs of the head's pre-activations; s / ds / sw (T, Q), (T, Q, 2), (T, Q) the points'
distances, gradients and soft-minimum weights, m / y (T,) the soft minimum and the head's
output."""

if AVAILABLE:
    from .fused import _jit, _leaky_rows
    from .fused_net_backward import _backward_tile
    from .fused_net_distances import tile_distances
    from .fused_net_readout import _head, _readout
    from .fused_search import point_candidates, softmax_groups
    from .gemm import mm

    @_jit
    def _nearest(p0, p1, partners, offset, idx, near, lphi):
        """idx, near, lphi (C,) of the point (p0, p1): its min(C, m) nearest rows of partners
        (m, 2) (+ offset), ascending d², log φ = log max(d²_last − d², 1e-12); the rest padded
        (d² PAD_DIST2, log φ NO_WEIGHT: weight 0)."""
        cand = idx.shape[0]
        real = min(cand, partners.shape[0])
        for c in range(cand):
            near[c] = PAD_DIST2
            idx[c] = offset
        for j in range(partners.shape[0]):
            dx = p0 - partners[j, 0]
            dy = p1 - partners[j, 1]
            dd = dx * dx + dy * dy
            if dd < near[real - 1]:
                c = real - 1
                while c > 0 and near[c - 1] > dd:
                    near[c] = near[c - 1]
                    idx[c] = idx[c - 1]
                    c -= 1
                near[c] = dd
                idx[c] = j + offset
        for c in range(cand):
            lphi[c] = np.log(max(near[real - 1] - near[c], 1e-12)) if c < real else NO_WEIGHT

    @_jit
    def _candidates(x, net, st):
        """st.xu ← the tile's union coordinates; st.idx, near, lphi ← every row's candidates:
        robot rows among the obstacle nodes (one-way: their index; two-way: their union row),
        obstacle rows (two-way) among the configuration's robot rows."""
        t_n, n_r, _ = x.shape
        n = net.ring.shape[1]
        offset = n_r if n > n_r else 0
        for t in range(t_n):
            for i in range(n):
                for j in range(2):
                    st.xu[t, i, j] = x[t, i, j] if i < n_r else net.xo[i - n_r, j]
        point_candidates(x, net.xo, offset, st.idx[:t_n, :n_r], st.near[:t_n, :n_r],
                         st.lphi[:t_n, :n_r])  # fmt: skip
        for t in range(t_n):
            for i in range(n_r, n):
                p0, p1 = st.xu[t, i, 0], st.xu[t, i, 1]
                _nearest(p0, p1, st.xu[t, :n_r], 0, st.idx[t, i], st.near[t, i], st.lphi[t, i])

    @_jit
    def _soft_weights(net, st, k, t_n, two_way):
        """st.w[k] ← softmax_c (log φ − d²/τ_k + s_k,j): s the partners' readout scores of
        layer k − 1 (two-way, k ≥ 1) or the scene's (one-way)."""
        n, cand = st.idx.shape[1], st.idx.shape[2]
        zero = net.scale * 0  # in the tile's dtype
        w3 = st.w[k]
        for t in range(t_n):
            for i in range(n):
                for c in range(cand):
                    j = st.idx[t, i, c]
                    if two_way:
                        s = st.logit[k - 1, t, j] if k else zero
                    else:
                        s = net.score[k, j]
                    w3[t, i, c] = st.lphi[t, i, c] - st.near[t, i, c] / net.tau[k] + s
        softmax_groups(w3.reshape(-1)[: t_n * n * cand], cand)

    @_jit
    def _node_terms(net, st, k, t_n, two_way):
        """(uv (T n, 2H), cc (T n, H)): [u v] = z A_k and c = Σ_c w_c v_{j_c} − v + b1."""
        n, cand = st.idx.shape[1], st.idx.shape[2]
        h = net.att.shape[1]
        rows = t_n * n
        dtype = st.xu.dtype
        uv = mm(st.h[k - 1, :rows], net.ah[k]) if k else np.zeros((rows, 2 * h), dtype)
        for t in range(t_n):
            for i in range(n):
                r = t * n + i
                for o in range(2 * h):
                    uv[r, o] += st.xu[t, i, 0] * net.ax[k, 0, o] + st.xu[t, i, 1] * net.ax[k, 1, o]
        if two_way:  # the partners' v are this configuration's rows, kept for the backward
            st.v[k, :rows] = uv[:, h:]
        cc = np.empty((rows, h), dtype)
        w = st.w[k]
        partners = st.v[k] if two_way else net.v[k]  # (T n, H) this tile's rows, or (M, H)
        for t in range(t_n):
            base = t * n if two_way else 0
            for i in range(n):
                r = t * n + i
                for o in range(h):
                    cc[r, o] = net.b1[k, o] - uv[r, h + o]
                if net.din.shape[1]:  # one-way: every row is a robot node, s_i its distance
                    for o in range(h):
                        cc[r, o] += st.s[t, i] * net.din[k, o]
                for c in range(cand):  # a partner's row at a time: contiguous, vectorised
                    row = base + st.idx[t, i, c]
                    wc = w[t, i, c]
                    for o in range(h):
                        cc[r, o] += wc * partners[row, o]
        return uv, cc

    @_jit
    def _edge_mlp(net, st, k, t_n, uv, cc):
        """st.h[k] ← W_L Σ_e g(pre_e) + 3 b_L of the tile (st.mask[k] ← the signs)."""
        n = st.idx.shape[1]
        h = net.att.shape[1]
        rows = t_n * n
        a = np.empty((3 * rows, h), st.xu.dtype)  # edge rows (prev, next, self) per config
        for t in range(t_n):
            base = 3 * n * t
            for i in range(n):
                r = t * n + i
                jp = t * n + net.ring[0, i]
                jn = t * n + net.ring[1, i]
                for o in range(h):
                    ci = cc[r, o] - uv[r, o]
                    a[base + i, o] = uv[jp, o] + ci
                    a[base + n + i, o] = uv[jn, o] + ci
                    a[base + 2 * n + i, o] = cc[r, o]
        _leaky_rows(a, np.empty(0, a.dtype), st.mask[k, 0], net.slope)
        for layer in range(net.wht.shape[1]):
            a = mm(a, net.wht[k, layer])
            _leaky_rows(a, net.bh[k, layer], st.mask[k, layer + 1], net.slope)
        msg = np.empty((rows, h), a.dtype)
        for t in range(t_n):
            base = 3 * n * t
            for i in range(n):
                r = base + i
                for o in range(h):
                    msg[t * n + i, o] = a[r, o] + a[r + n, o] + a[r + 2 * n, o]
        hk = st.h[k, :rows]
        hk[:] = mm(msg, net.wlt[k])
        for r in range(rows):
            for o in range(h):
                hk[r, o] += net.bl3[k, o]

    @_jit
    def _forward_tile(x, net, st, d_out):
        """d_out (T,) ← d̂ of the tile's normalised robot nodes x (T, N_r, 2); st ← what the
        backward needs."""
        t_n, n_r, _ = x.shape
        layers = net.att.shape[0]
        two_way = net.ring.shape[1] > n_r
        _candidates(x, net, st)
        if net.din.shape[1]:
            tile_distances(x, net, st.s, st.ds)
        pooled = np.empty((t_n, net.h0t.shape[0]), x.dtype)
        for k in range(layers):
            _soft_weights(net, st, k, t_n, two_way)
            uv, cc = _node_terms(net, st, k, t_n, two_way)
            _edge_mlp(net, st, k, t_n, uv, cc)
            _readout(net, st, k, t_n, n_r, pooled)
        _head(net, st, pooled, d_out)

    @_jit
    def new_state(x, net, cand, tile):
        """An empty :class:`State` for tiles of up to ``tile`` configurations of robot nodes
        like x (B, N_r, 2) (their count and dtype)."""
        n_r = x.shape[1]
        n = net.ring.shape[1]
        layers, h = net.att.shape
        dt = x.dtype
        hidden, width = net.wht.shape[1], net.h0t.shape[0]
        points = n_r * net.probe if net.din.shape[1] else 0
        return State(
            np.empty((tile, n, 2), dt),
            np.empty((tile, n, cand), np.int64),
            np.empty((tile, n, cand), dt),
            np.empty((tile, n, cand), dt),
            np.empty((layers, tile, n, cand), dt),
            np.empty((layers, tile * n if n > n_r else 0, h), dt),
            np.empty((layers, tile * n, h), dt),
            np.empty((layers, hidden + 1, 3 * tile * n, h), np.bool_),
            np.empty((layers, tile, n), dt),
            np.empty((layers, tile, n), dt),
            np.empty((layers, tile, width), np.bool_),
            np.empty((tile, width), np.int64),
            np.empty((net.hw.shape[0] + 1, tile, net.wlast.shape[0]), np.bool_),
            np.empty((tile, points), dt),
            np.empty((tile, points, 2), dt),
            np.empty((tile, points), dt),
            np.empty(tile, dt),
            np.empty(tile, dt),
        )

    @_jit
    def network(x, net, cand, d_out, g_out, tile):
        """d_out (B,) ← d̂ of normalised robot nodes x (B, N_r, 2); g_out (B, N_r, 2) ← ∂d̂/∂x
        (skipped when g_out has no rows), ``tile`` configurations at a time."""
        st = new_state(x, net, cand, tile)
        for b0 in range(0, x.shape[0], tile):
            b1 = min(b0 + tile, x.shape[0])
            _forward_tile(x[b0:b1], net, st, d_out[b0:b1])
            if g_out.shape[0] > 0:
                _backward_tile(x[b0:b1], net, st, g_out[b0:b1])
