"""The reverse pass of :mod:`.fused_net` on one tile (numba; the math is in that module's
docstring): from the state :func:`.fused_net_kernels._forward_tile` kept, ∂d̂/∂x of the tile's
normalised robot nodes, head → readout maximum → per layer (last to first) readout softmax,
edge MLP, [∂u ∂v], cross weights → candidates' d² → x.
"""

from __future__ import annotations

import numpy as np

from .fused import AVAILABLE

if AVAILABLE:
    from .fused import _jit

    @_jit
    def _backward_tile(
        x,
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
        g_out,
    ):
        """g_out (T, n, 2) ← ∂d̂/∂x of the tile (x normalised) from :func:`_forward_tile`'s state."""
        t_n, n, _ = x.shape
        layers, h = att.shape
        cand = st_idx.shape[2]
        rows = t_n * n
        zero = scale * 0
        hl = hw.shape[0]
        g = np.empty((t_n, wlast.shape[0]), x.dtype)
        for t in range(t_n):
            for o in range(wlast.shape[0]):
                gv = wlast[o] * scale
                g[t, o] = gv if st_hmask[hl, t, o] else gv * slope
        for layer in range(hl - 1, -1, -1):
            g = np.dot(g, hw[layer])
            for t in range(t_n):
                for o in range(g.shape[1]):
                    if not st_hmask[layer, t, o]:
                        g[t, o] *= slope
        dy = np.dot(g, h0)  # (T, H): ∂/∂y_r
        dh = np.zeros((rows, h), x.dtype)  # ∂/∂h⁽ᵏ⁾ from the layers above
        dlphi = np.zeros((t_n, n, cand), x.dtype)
        dnear = np.zeros((t_n, n, cand), x.dtype)
        gy = np.empty(h, x.dtype)
        da = np.empty(n, x.dtype)
        dw = np.empty(cand, x.dtype)
        for k in range(layers - 1, -1, -1):
            hk = st_h[k]
            for t in range(t_n):  # readout: y = σ(Σ α_i h_i), α = softmax a_kᵀ h
                for o in range(h):
                    gv = dy[t, o] if st_src[t, o] == k else zero
                    gy[o] = gv if st_ypos[k, t, o] else gv * slope
                mean = zero
                for i in range(n):
                    acc = zero
                    for o in range(h):
                        acc += hk[t * n + i, o] * gy[o]
                    da[i] = acc
                    alpha = st_alpha[k, t, i]
                    mean += alpha * acc
                    for o in range(h):
                        dh[t * n + i, o] += alpha * gy[o]
                for i in range(n):
                    ds = st_alpha[k, t, i] * (da[i] - mean)
                    for o in range(h):
                        dh[t * n + i, o] += ds * att[k, o]
            dmsg = np.dot(dh, wl[k])
            a = np.empty((3 * rows, h), x.dtype)
            top = st_mask[k, st_mask.shape[1] - 1]
            for t in range(t_n):
                base = 3 * n * t
                for e in range(3):
                    for i in range(n):
                        r = base + e * n + i
                        for o in range(h):
                            gv = dmsg[t * n + i, o]
                            a[r, o] = gv if top[r, o] else gv * slope
            for layer in range(wh.shape[1] - 1, -1, -1):
                a = np.dot(a, wh[k, layer])
                m = st_mask[k, layer]
                for r in range(3 * rows):
                    for o in range(h):
                        if not m[r, o]:
                            a[r, o] *= slope
            duv = np.zeros((rows, 2 * h), x.dtype)  # [∂u, ∂v], ∂v = −∂c
            for t in range(t_n):
                base = 3 * n * t
                for i in range(n):
                    r = t * n + i
                    jp = t * n + ring[0, i]
                    jn = t * n + ring[1, i]
                    for o in range(h):
                        gp = a[base + i, o]
                        gn = a[base + n + i, o]
                        duv[r, h + o] -= gp + gn + a[base + 2 * n + i, o]
                        duv[r, o] -= gp + gn
                        duv[jp, o] += gp
                        duv[jn, o] += gn
            w = st_w[k]
            for t in range(t_n):  # cross weights, softmax, ∂ℓ → ∂d², ∂log φ; ∂x from z
                for i in range(n):
                    r = t * n + i
                    mean = zero
                    for c in range(cand):
                        acc = zero
                        for o in range(h):
                            acc -= duv[r, h + o] * v[k, st_idx[t, i, c], o]
                        dw[c] = acc
                        mean += w[t, i, c] * acc
                    for c in range(cand):
                        dl = w[t, i, c] * (dw[c] - mean)
                        dlphi[t, i, c] += dl
                        dnear[t, i, c] -= dl / tau[k]
                    for j in range(2):
                        acc = zero
                        for o in range(2 * h):
                            acc += duv[r, o] * ax[k, j, o]
                        g_out[t, i, j] += acc
            if k:
                dh = np.dot(duv, aht[k])
        for t in range(t_n):  # log φ, then d² = |x − x_o|²
            for i in range(n):
                last = st_near[t, i, cand - 1]
                for c in range(cand - 1):
                    delta = last - st_near[t, i, c]
                    if delta >= 1e-12:
                        q = dlphi[t, i, c] / delta
                        dnear[t, i, cand - 1] += q
                        dnear[t, i, c] -= q
                for c in range(cand):
                    j = st_idx[t, i, c]
                    g_out[t, i, 0] += 2 * (x[t, i, 0] - xo[j, 0]) * dnear[t, i, c]
                    g_out[t, i, 1] += 2 * (x[t, i, 1] - xo[j, 1]) * dnear[t, i, c]
