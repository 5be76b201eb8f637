"""The compiled kernels of :mod:`.fused_net` (numba; the math is in that module's docstring).

:func:`network` loops over tiles of configurations; per tile :func:`_forward_tile` runs the
network and keeps what the backward needs (candidates, soft weights, signs of the
pre-activations, features, readout weights), and with the gradient
:func:`.fused_net_backward._backward_tile` runs the reverse pass at once. Shapes: T
configurations per tile, n robot nodes, C candidates, K layers, H features, L hidden
layers of the edge MLP, R readout width.
"""

from __future__ import annotations

import numpy as np

from .fused import AVAILABLE

if AVAILABLE:
    from .fused import _jit, _leaky_rows
    from .fused_net_backward import _backward_tile

    @_jit
    def _candidates(x, xo, cand, idx, near, lphi):
        """idx, near (T, n, C): the C nearest obstacle nodes of every x (T, n, 2), ascending
        d²; lphi = log max(d²_C − d², 1e-12)."""
        t_n, n, _ = x.shape
        m = xo.shape[0]
        for t in range(t_n):
            for i in range(n):
                x0 = x[t, i, 0]
                x1 = x[t, i, 1]
                for c in range(cand):
                    near[t, i, c] = np.inf
                    idx[t, i, c] = 0
                for j in range(m):
                    dx = x0 - xo[j, 0]
                    dy = x1 - xo[j, 1]
                    dd = dx * dx + dy * dy
                    if dd < near[t, i, cand - 1]:
                        c = cand - 1
                        while c > 0 and near[t, i, c - 1] > dd:
                            near[t, i, c] = near[t, i, c - 1]
                            idx[t, i, c] = idx[t, i, c - 1]
                            c -= 1
                        near[t, i, c] = dd
                        idx[t, i, c] = j
                for c in range(cand):
                    lphi[t, i, c] = np.log(max(near[t, i, cand - 1] - near[t, i, c], 1e-12))

    @_jit
    def _forward_tile(
        x,
        xo,
        ring,
        tau,
        score,
        v,
        ax,
        ah,
        b1,
        wht,
        bh,
        wlt,
        bl3,
        att,
        h0t,
        hb0,
        hwt,
        hb,
        wlast,
        blast,
        scale,
        slope,
        st_idx,
        st_near,
        st_lphi,
        st_w,
        st_h,
        st_mask,
        st_alpha,
        st_ypos,
        st_src,
        st_hmask,
        d_out,
    ):
        """d_out (T,) ← d̂ of the tile x (T, n, 2); the st_* buffers ← what the backward needs."""
        t_n, n, _ = x.shape
        layers, h = att.shape
        cand = st_idx.shape[2]
        rows = t_n * n
        zero = scale * 0  # accumulators in the tile's dtype
        _candidates(x, xo, cand, st_idx, st_near, st_lphi)
        pooled = np.empty((t_n, h), x.dtype)
        empty = np.empty(0, x.dtype)
        for k in range(layers):
            w = st_w[k]
            for t in range(t_n):  # soft weights over the candidates
                for i in range(n):
                    top = -np.inf
                    for c in range(cand):
                        j = st_idx[t, i, c]
                        lg = st_lphi[t, i, c] - st_near[t, i, c] / tau[k] + score[k, j]
                        w[t, i, c] = lg
                        top = max(top, lg)
                    total = zero
                    for c in range(cand):
                        e = np.exp(w[t, i, c] - top)
                        w[t, i, c] = e
                        total += e
                    for c in range(cand):
                        w[t, i, c] /= total
            if k:  # [u v] = z A_k: the h part by BLAS, the two coordinates as loops
                uv = np.dot(st_h[k - 1, :rows], ah[k])
            else:
                uv = np.zeros((rows, 2 * h), x.dtype)
            cc = np.empty((rows, h), x.dtype)
            for t in range(t_n):
                for i in range(n):
                    r = t * n + i
                    for o in range(2 * h):
                        uv[r, o] += x[t, i, 0] * ax[k, 0, o] + x[t, i, 1] * ax[k, 1, o]
                    for o in range(h):
                        acc = zero
                        for c in range(cand):
                            acc += w[t, i, c] * v[k, st_idx[t, i, c], o]
                        cc[r, o] = acc - uv[r, h + o] + b1[k, o]
            a = np.empty((3 * rows, h), x.dtype)  # edge rows (prev, next, self) per config
            for t in range(t_n):
                base = 3 * n * t
                for i in range(n):
                    r = t * n + i
                    jp = t * n + ring[0, i]
                    jn = t * n + ring[1, i]
                    for o in range(h):
                        ci = cc[r, o] - uv[r, o]
                        a[base + i, o] = uv[jp, o] + ci
                        a[base + n + i, o] = uv[jn, o] + ci
                        a[base + 2 * n + i, o] = cc[r, o]
            _leaky_rows(a, empty, st_mask[k, 0], slope)
            for layer in range(wht.shape[1]):
                a = np.dot(a, wht[k, layer])
                _leaky_rows(a, bh[k, layer], st_mask[k, layer + 1], slope)
            msg = np.empty((rows, h), x.dtype)
            for t in range(t_n):
                base = 3 * n * t
                for i in range(n):
                    for o in range(h):
                        r = base + i
                        msg[t * n + i, o] = a[r, o] + a[r + n, o] + a[r + 2 * n, o]
            hk = st_h[k, :rows]
            hk[:] = np.dot(msg, wlt[k])
            for r in range(rows):
                for o in range(h):
                    hk[r, o] += bl3[k, o]
            for t in range(t_n):  # readout: α = softmax_i a_kᵀ h_i, y = σ(Σ α_i h_i), max over k
                top = -np.inf
                for i in range(n):
                    s = zero
                    for o in range(h):
                        s += hk[t * n + i, o] * att[k, o]
                    st_alpha[k, t, i] = s
                    top = max(top, s)
                total = zero
                for i in range(n):
                    e = np.exp(st_alpha[k, t, i] - top)
                    st_alpha[k, t, i] = e
                    total += e
                for i in range(n):
                    st_alpha[k, t, i] /= total
                for o in range(h):
                    y = zero
                    for i in range(n):
                        y += st_alpha[k, t, i] * hk[t * n + i, o]
                    st_ypos[k, t, o] = y > 0
                    y = y if y > 0 else y * slope
                    if k == 0 or y > pooled[t, o]:
                        pooled[t, o] = y
                        st_src[t, o] = k
        a = np.dot(pooled, h0t)  # the head (its obstacle half is in hb0)
        _leaky_rows(a, hb0, st_hmask[0], slope)
        for layer in range(hwt.shape[0]):
            a = np.dot(a, hwt[layer])
            _leaky_rows(a, hb[layer], st_hmask[layer + 1], slope)
        for t in range(t_n):
            out = blast[0]
            for o in range(a.shape[1]):
                out += a[t, o] * wlast[o]
            d_out[t] = out * scale

    @_jit
    def network(
        x,
        xo,
        ring,
        tau,
        score,
        v,
        ax,
        ah,
        aht,
        b1,
        wht,
        wh,
        bh,
        wlt,
        wl,
        bl3,
        att,
        h0t,
        h0,
        hb0,
        hwt,
        hw,
        hb,
        wlast,
        blast,
        cand,
        d_out,
        g_out,
        scale,
        slope,
        tile,
    ):
        """d_out (B,) ← d̂ of normalised robot nodes x (B, n, 2); g_out (B, n, 2) ← ∂d̂/∂x
        (skipped when g_out has no rows), ``tile`` configurations at a time."""
        bsz, n, _ = x.shape
        layers, h = att.shape
        st_idx = np.empty((tile, n, cand), np.int64)
        st_near = np.empty((tile, n, cand), x.dtype)
        st_lphi = np.empty((tile, n, cand), x.dtype)
        st_w = np.empty((layers, tile, n, cand), x.dtype)
        st_h = np.empty((layers, tile * n, h), x.dtype)
        st_mask = np.empty((layers, wht.shape[1] + 1, 3 * tile * n, h), np.bool_)
        st_alpha = np.empty((layers, tile, n), x.dtype)
        st_ypos = np.empty((layers, tile, h), np.bool_)
        st_src = np.empty((tile, h), np.int64)
        st_hmask = np.empty((hw.shape[0] + 1, tile, wlast.shape[0]), np.bool_)
        grad = g_out.shape[0] > 0
        for b0 in range(0, bsz, tile):
            b1_ = min(b0 + tile, bsz)
            xt = x[b0:b1_]
            _forward_tile(
                xt,
                xo,
                ring,
                tau,
                score,
                v,
                ax,
                ah,
                b1,
                wht,
                bh,
                wlt,
                bl3,
                att,
                h0t,
                hb0,
                hwt,
                hb,
                wlast,
                blast,
                scale,
                slope,
                st_idx,
                st_near,
                st_lphi,
                st_w,
                st_h,
                st_mask,
                st_alpha,
                st_ypos,
                st_src,
                st_hmask,
                d_out[b0:b1_],
            )
            if grad:
                _backward_tile(
                    xt,
                    xo,
                    ring,
                    tau,
                    v,
                    ax,
                    aht,
                    wh,
                    wl,
                    att,
                    h0,
                    hw,
                    wlast,
                    scale,
                    slope,
                    st_idx,
                    st_near,
                    st_w,
                    st_h,
                    st_mask,
                    st_alpha,
                    st_ypos,
                    st_src,
                    st_hmask,
                    g_out[b0:b1_],
                )
