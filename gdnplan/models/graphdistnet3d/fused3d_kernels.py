"""The compiled forward pass of :mod:`.fused3d` (numba; the math is in that module's docstring).

:func:`network` loops over tiles of configurations; per tile :func:`_forward_tile` runs the
network and keeps what the backward needs in a :class:`State` (candidates, soft weights, signs
of the pre-activations, features, readout weights), and with the gradient
:func:`.fused3d_backward._backward_tile` runs the reverse pass at once. Shapes: T
configurations per tile, n robot nodes, E directed graph edges (Σ_i deg i), C candidates, K
layers, H = d_h features, P the edge MLP's hidden width, L its hidden products, R the head's
width. Edge rows of configuration t: t (E + n) + e for edge e (grouped by source node,
``ptr``), then t (E + n) + E + i for the self edge of node i.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ..graphdistnet.fused import AVAILABLE


class Weights(NamedTuple):
    """The network and one scene's constants as contiguous arrays of one dtype (M obstacle
    nodes): xo (M, 3), tau (K,), score (K, M) (zeros at k = 0), v (K, M, P),
    ax (K, 3, 2P), ah (K, H, 2P) (zeros at k = 0) and aht (K, 2P, H), b1 (K, P),
    wht / wh (K, L, P, P) (transposed / not), bh (K, L, P), wlt (K, P, H) / wl (K, H, P),
    bl (K, H), att (K, H), h0t (H, R) / h0 (R, H), hb0 (R,), hwt / hw (Lr, R, R), hb (Lr, R),
    wlast (R,), blast (1,)."""

    xo: np.ndarray
    tau: np.ndarray
    score: np.ndarray
    v: np.ndarray
    ax: np.ndarray
    ah: np.ndarray
    aht: np.ndarray
    b1: np.ndarray
    wht: np.ndarray
    wh: np.ndarray
    bh: np.ndarray
    wlt: np.ndarray
    wl: np.ndarray
    bl: np.ndarray
    att: np.ndarray
    h0t: np.ndarray
    h0: np.ndarray
    hb0: np.ndarray
    hwt: np.ndarray
    hw: np.ndarray
    hb: np.ndarray
    wlast: np.ndarray
    blast: np.ndarray


class Graph(NamedTuple):
    """The robot graph's directed edges: src, dst (E,) int64 grouped by source, ptr (n + 1,)
    int64 (node i's edges ptr[i] … ptr[i + 1] − 1) and cnt (n,) = deg i + 1 (the dtype's)."""

    src: np.ndarray
    dst: np.ndarray
    ptr: np.ndarray
    cnt: np.ndarray


class State(NamedTuple):
    """What the backward needs of one tile: idx, near (d²), lphi (T, n, C); w (K, T, n, C);
    h (K, T n, H); mask (K, L + 1, T (E + n), P) and hmask (Lr + 1, T, R) signs of the
    pre-activations; alpha (K, T, n); ypos (K, T, H) signs of the pooled sums; src (T, H) the
    layer each pooled feature came from."""

    idx: np.ndarray
    near: np.ndarray
    lphi: np.ndarray
    w: np.ndarray
    h: np.ndarray
    mask: np.ndarray
    alpha: np.ndarray
    ypos: np.ndarray
    src: np.ndarray
    hmask: np.ndarray


if AVAILABLE:
    from ..graphdistnet.fused import _jit, _leaky_rows
    from ..graphdistnet.fused_search import point_candidates, softmax_groups
    from ..graphdistnet.gemm import mm
    from .fused3d_backward import _backward_tile

    @_jit
    def _soft_weights(k, t_n, wts, st):
        """st.w[k] ← softmax_c (log φ − d²/τ_k + s_k,j_c) of every node of the tile's first
        t_n configurations."""
        w = st.w[k]
        n, cand = st.idx.shape[1], st.idx.shape[2]
        for t in range(t_n):
            for i in range(n):
                for c in range(cand):
                    lg = st.lphi[t, i, c] - st.near[t, i, c] / wts.tau[k]
                    w[t, i, c] = lg + wts.score[k, st.idx[t, i, c]]
        softmax_groups(w.reshape(-1)[: t_n * n * cand], cand)

    @_jit
    def _readout(k, hk, wts, st, pooled, slope):
        """α = softmax_i a_kᵀ h_i, y = σ(Σ_i α_i h_i); pooled (T, H) ← max(pooled, y)."""
        t_n, n = pooled.shape[0], st.alpha.shape[2]
        h = hk.shape[1]
        zero = hk[0, 0] * 0
        ys = np.empty(h, hk.dtype)
        for t in range(t_n):
            top = zero
            for i in range(n):
                s = zero
                for o in range(h):
                    s += hk[t * n + i, o] * wts.att[k, o]
                st.alpha[k, t, i] = s
                top = s if i == 0 else max(top, s)
            total = zero
            for i in range(n):
                e = np.exp(st.alpha[k, t, i] - top)
                st.alpha[k, t, i] = e
                total += e
            for i in range(n):
                st.alpha[k, t, i] /= total
            ys[:] = zero
            for i in range(n):
                alpha = st.alpha[k, t, i]
                for o in range(h):
                    ys[o] += alpha * hk[t * n + i, o]
            for o in range(h):
                y = ys[o]
                st.ypos[k, t, o] = y > 0
                y = y if y > 0 else y * slope
                if k == 0 or y > pooled[t, o]:
                    pooled[t, o] = y
                    st.src[t, o] = k

    @_jit
    def _forward_tile(x, wts, graph, st, scale, slope, keep, d_out):
        """d_out (T,) ← d̂ of the tile x (T, n, 3) (normalised); st ← what the backward needs
        (the signs of the pre-activations only with ``keep``)."""
        t_n, n, _ = x.shape
        layers, h = wts.att.shape
        p = wts.b1.shape[1]
        n_e = graph.src.shape[0]
        per = n_e + n  # edge rows per configuration
        rows, e_rows = t_n * n, t_n * per
        point_candidates(x, wts.xo, 0, st.idx, st.near, st.lphi)
        pooled = np.empty((t_n, h), x.dtype)
        nomask = np.empty((0, p), np.bool_)
        for k in range(layers):
            _soft_weights(k, t_n, wts, st)
            w = st.w[k]
            if k:  # [u v] = z A_k: the h part by BLAS, the three coordinates as loops
                uv = mm(st.h[k - 1, :rows], wts.ah[k])
            else:
                uv = np.zeros((rows, 2 * p), x.dtype)
            cc = np.empty((rows, p), x.dtype)  # c_i = Σ_c w_ic V_k,j_c − v_i + b_k
            for t in range(t_n):
                for i in range(n):
                    r = t * n + i
                    for o in range(2 * p):
                        uv[r, o] += (
                            x[t, i, 0] * wts.ax[k, 0, o]
                            + x[t, i, 1] * wts.ax[k, 1, o]
                            + x[t, i, 2] * wts.ax[k, 2, o]
                        )
                    for o in range(p):
                        cc[r, o] = 0
                    for c in range(w.shape[2]):
                        wc, j = w[t, i, c], st.idx[t, i, c]
                        for o in range(p):
                            cc[r, o] += wc * wts.v[k, j, o]
                    for o in range(p):
                        cc[r, o] = cc[r, o] - uv[r, p + o] + wts.b1[k, o]
            a = np.empty((e_rows, p), x.dtype)  # σ(pre), pre = u_j − u_i + c_i; self: c_i
            m0 = st.mask[k, 0]
            for t in range(t_n):
                base, off = t * per, t * n
                for e in range(n_e):
                    i, j = off + graph.src[e], off + graph.dst[e]
                    for o in range(p):
                        s = (uv[j, o] - uv[i, o]) + cc[i, o]
                        a[base + e, o] = s if s > 0 else s * slope
                        if keep:
                            m0[base + e, o] = s > 0
                for i in range(n):
                    for o in range(p):
                        s = cc[off + i, o]
                        a[base + n_e + i, o] = s if s > 0 else s * slope
                        if keep:
                            m0[base + n_e + i, o] = s > 0
            for layer in range(wts.wht.shape[1]):
                a = mm(a, wts.wht[k, layer])
                m = st.mask[k, layer + 1, :e_rows] if keep else nomask
                _leaky_rows(a, wts.bh[k, layer], m, slope)
            msg = np.empty((rows, p), x.dtype)  # Σ over node i's edges and itself
            for t in range(t_n):
                base = t * per
                for i in range(n):
                    for o in range(p):
                        msg[t * n + i, o] = a[base + n_e + i, o]
                    for e in range(graph.ptr[i], graph.ptr[i + 1]):
                        for o in range(p):
                            msg[t * n + i, o] += a[base + e, o]
            hk = st.h[k, :rows]
            hk[:] = mm(msg, wts.wlt[k])
            for t in range(t_n):
                for i in range(n):
                    for o in range(h):
                        hk[t * n + i, o] += graph.cnt[i] * wts.bl[k, o]
            _readout(k, hk, wts, st, pooled, slope)
        a = mm(pooled, wts.h0t)  # the head (its obstacle half is in hb0)
        _leaky_rows(a, wts.hb0, st.hmask[0, :t_n], slope)
        for layer in range(wts.hwt.shape[0]):
            a = mm(a, wts.hwt[layer])
            _leaky_rows(a, wts.hb[layer], st.hmask[layer + 1, :t_n], slope)
        for t in range(t_n):
            out = wts.blast[0]
            for o in range(a.shape[1]):
                out += a[t, o] * wts.wlast[o]
            d_out[t] = out * scale

    @_jit
    def network(x, wts, graph, cand, tile, scale, slope, d_out, g_out):
        """d_out (B,) ← d̂ of normalised robot nodes x (B, n, 3); g_out (B, n, 3) ← ∂d̂/∂x
        (skipped when g_out has no rows), ``tile`` configurations at a time."""
        bsz, n, _ = x.shape
        layers, h = wts.att.shape
        p = wts.b1.shape[1]
        per = graph.src.shape[0] + n
        grad = g_out.shape[0] > 0
        st = State(
            np.empty((tile, n, cand), np.int64),
            np.empty((tile, n, cand), x.dtype),
            np.empty((tile, n, cand), x.dtype),
            np.empty((layers, tile, n, cand), x.dtype),
            np.empty((layers, tile * n, h), x.dtype),
            np.empty((layers, wts.wht.shape[1] + 1, tile * per if grad else 0, p), np.bool_),
            np.empty((layers, tile, n), x.dtype),
            np.empty((layers, tile, h), np.bool_),
            np.empty((tile, h), np.int64),
            np.empty((wts.hwt.shape[0] + 1, tile, wts.wlast.shape[0]), np.bool_),
        )
        for b0 in range(0, bsz, tile):
            b1 = min(b0 + tile, bsz)
            _forward_tile(x[b0:b1], wts, graph, st, scale, slope, grad, d_out[b0:b1])
            if grad:
                _backward_tile(x[b0:b1], wts, graph, st, scale, slope, g_out[b0:b1])
