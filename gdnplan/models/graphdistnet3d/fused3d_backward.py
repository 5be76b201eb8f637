"""The reverse pass of :mod:`.fused3d` on one tile (numba; the math is in that module's
docstring): from the :class:`~.fused3d_kernels.State` that
:func:`.fused3d_kernels._forward_tile` kept, ∂d̂/∂x of the tile's normalised robot nodes, head →
readout maximum → per layer (last to first) readout softmax, edge MLP, [∂u ∂v], cross weights →
candidates' d² → x. Shapes as in :mod:`.fused3d_kernels`.
"""

from __future__ import annotations

import numpy as np

from ..graphdistnet.fused import AVAILABLE

if AVAILABLE:
    from ..graphdistnet.fused import _jit, _log_phi_backward
    from ..graphdistnet.gemm import mm

    @_jit
    def _head_backward(wts, st, t_n, scale, slope):
        """(T, H) ∂d̂/∂y_r through the head's hidden layers."""
        hl = wts.hw.shape[0]
        r = wts.wlast.shape[0]
        g = np.empty((t_n, r), wts.wlast.dtype)
        for t in range(t_n):
            for o in range(r):
                gv = wts.wlast[o] * scale
                g[t, o] = gv if st.hmask[hl, t, o] else gv * slope
        for layer in range(hl - 1, -1, -1):
            g = mm(g, wts.hw[layer])
            for t in range(t_n):
                for o in range(r):
                    if not st.hmask[layer, t, o]:
                        g[t, o] *= slope
        return mm(g, wts.h0)

    @_jit
    def _readout_backward(k, dy, wts, st, dh, slope):
        """dh (T n, H) += ∂/∂h⁽ᵏ⁾ of y = σ(Σ_i α_i h_i), α = softmax_i a_kᵀ h_i, given ∂/∂y_r
        dy (T, H) (to the layer the maximum came from)."""
        t_n, n = dy.shape[0], st.alpha.shape[2]
        h = dh.shape[1]
        hk = st.h[k]
        zero = dh[0, 0] * 0
        gy = np.empty(h, dh.dtype)
        da = np.empty(n, dh.dtype)
        for t in range(t_n):
            for o in range(h):
                gv = dy[t, o] if st.src[t, o] == k else zero
                gy[o] = gv if st.ypos[k, t, o] else gv * slope
            mean = zero
            for i in range(n):
                acc = zero
                for o in range(h):
                    acc += hk[t * n + i, o] * gy[o]
                da[i] = acc
                alpha = st.alpha[k, t, i]
                mean += alpha * acc
                for o in range(h):
                    dh[t * n + i, o] += alpha * gy[o]
            for i in range(n):
                ds = st.alpha[k, t, i] * (da[i] - mean)
                for o in range(h):
                    dh[t * n + i, o] += ds * wts.att[k, o]

    @_jit
    def _edges_backward(k, dh, wts, graph, st, t_n, slope):
        """[∂u ∂v] (T n, 2P) of layer k from ∂/∂h⁽ᵏ⁺¹⁾ dh (T n, H): the last linear layer, the
        edge MLP (signs kept), pre = u_j − u_i + c_i, c_i = … − v_i."""
        n = graph.cnt.shape[0]
        n_e = graph.src.shape[0]
        per = n_e + n
        p = wts.b1.shape[1]
        dmsg = mm(dh, wts.wl[k])  # (T n, P)
        a = np.empty((t_n * per, p), dh.dtype)
        top = st.mask[k, st.mask.shape[1] - 1]
        for t in range(t_n):
            base, off = t * per, t * n
            for e in range(n_e):
                i = off + graph.src[e]
                r = base + e
                for o in range(p):
                    gv = dmsg[i, o]
                    a[r, o] = gv if top[r, o] else gv * slope
            for i in range(n):
                r = base + n_e + i
                for o in range(p):
                    gv = dmsg[off + i, o]
                    a[r, o] = gv if top[r, o] else gv * slope
        for layer in range(wts.wh.shape[1] - 1, -1, -1):
            a = mm(a, wts.wh[k, layer])
            m = st.mask[k, layer]
            for r in range(a.shape[0]):
                for o in range(p):
                    a[r, o] = a[r, o] if m[r, o] else a[r, o] * slope
        duv = np.zeros((t_n * n, 2 * p), dh.dtype)  # [∂u, ∂v], ∂v = −∂c
        for t in range(t_n):
            base, off = t * per, t * n
            for e in range(n_e):
                i, j = off + graph.src[e], off + graph.dst[e]
                for o in range(p):
                    gv = a[base + e, o]
                    duv[j, o] += gv
                    duv[i, o] -= gv
                    duv[i, p + o] -= gv
            for i in range(n):
                for o in range(p):
                    duv[off + i, p + o] -= a[base + n_e + i, o]
        return duv

    @_jit
    def _backward_tile(x, wts, graph, st, scale, slope, g_out):
        """g_out (T, n, 3) ← ∂d̂/∂x of the tile (x normalised) from the forward's state."""
        t_n, n, _ = x.shape
        layers, h = wts.att.shape
        p = wts.b1.shape[1]
        cand = st.idx.shape[2]
        zero = scale * 0
        dy = _head_backward(wts, st, t_n, scale, slope)  # (T, H): ∂/∂y_r
        dh = np.zeros((t_n * n, h), x.dtype)  # ∂/∂h⁽ᵏ⁾ from the layers above
        dlphi = np.zeros((t_n, n, cand), x.dtype)
        dnear = np.zeros((t_n, n, cand), x.dtype)
        dw = np.empty(cand, x.dtype)
        for k in range(layers - 1, -1, -1):
            _readout_backward(k, dy, wts, st, dh, slope)
            duv = _edges_backward(k, dh, wts, graph, st, t_n, slope)
            w = st.w[k]
            for t in range(t_n):  # cross weights, softmax, ∂ℓ → ∂d², ∂log φ; ∂x from z
                for i in range(n):
                    r = t * n + i
                    mean = zero
                    for c in range(cand):
                        acc = zero
                        j = st.idx[t, i, c]
                        for o in range(p):
                            acc -= duv[r, p + o] * wts.v[k, j, o]
                        dw[c] = acc
                        mean += w[t, i, c] * acc
                    for c in range(cand):
                        dl = w[t, i, c] * (dw[c] - mean)
                        dlphi[t, i, c] += dl
                        dnear[t, i, c] -= dl / wts.tau[k]
                    for d in range(3):
                        acc = zero
                        for o in range(2 * p):
                            acc += duv[r, o] * wts.ax[k, d, o]
                        g_out[t, i, d] += acc
            if k:
                dh = mm(duv, wts.aht[k])
        for t in range(t_n):  # log φ, then d² = |x − x_o|²
            for i in range(n):
                _log_phi_backward(st.near[t, i], dlphi[t, i], dnear[t, i], cand)
                for c in range(cand):
                    j = st.idx[t, i, c]
                    for d in range(3):
                        g_out[t, i, d] += 2 * (x[t, i, d] - wts.xo[j, d]) * dnear[t, i, c]
