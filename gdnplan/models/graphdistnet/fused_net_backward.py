"""The reverse pass of :mod:`.fused_net` on one tile (numba; the math is in that module's
docstring): from the :class:`~.fused_net_kernels.State` the forward kept, ∂d̂/∂x of the
tile's normalised robot nodes, head → readout maximum → per layer (last to first) readout
softmax, edge MLP, [∂u ∂v], cross weights (two-way: and the partners' v and scores) →
candidates' d² → x. Obstacle rows (two-way) pass their gradient on to the robot rows they
depend on; their own coordinates are constants.
"""

from __future__ import annotations

import numpy as np

from .fused import AVAILABLE

if AVAILABLE:
    from .fused import _jit, _log_phi_backward
    from .fused_net_distances import points_backward
    from .fused_net_distances import readout as _distance_readout
    from .gemm import mm

    @_jit
    def _head_backward(net, st, t_n, gs):
        """(T, P) ∂d̂/∂pooled: the head's layers in reverse; with ``min_readout`` also gs
        (T, points) += ∂d̂/∂s through the soft minimum (the head's input and the readout)."""
        hl = net.hw.shape[0]
        r = net.wlast.shape[0]
        g = np.empty((t_n, r), st.xu.dtype)
        direct = np.zeros(t_n, st.xu.dtype)  # ∂d̂/∂m past the head
        for t in range(t_n):
            dy = net.scale
            if net.hm.shape[0]:
                _, dy, direct[t] = _distance_readout(net, st.m[t], st.y[t])
            for o in range(r):
                gv = net.wlast[o] * dy
                g[t, o] = gv if st.hmask[hl, t, o] else gv * net.slope
        for layer in range(hl - 1, -1, -1):
            g = mm(g, net.hw[layer])
            for t in range(t_n):
                for o in range(r):
                    if not st.hmask[layer, t, o]:
                        g[t, o] *= net.slope
        if net.hm.shape[0]:
            for t in range(t_n):
                dm = direct[t]
                for o in range(r):
                    dm += g[t, o] * net.hm[o]
                for p in range(gs.shape[1]):
                    gs[t, p] += dm * st.sw[t, p]
        return mm(g, net.h0)

    @_jit
    def _readout_backward(net, st, k, t_n, n_r, dy, dh):
        """dh (T n, H) += ∂/∂h⁽ᵏ⁾ of the readouts of layer k given dy = ∂/∂pooled (T, P)."""
        n = st.idx.shape[1]
        h = net.att.shape[1]
        hk = st.h[k]
        zero = net.scale * 0
        gy = np.empty(h, dh.dtype)
        da = np.empty(n, dh.dtype)
        for t in range(t_n):
            for graph in range(dy.shape[1] // h):
                lo, hi = (0, n_r) if graph == 0 else (n_r, n)
                for o in range(h):
                    col = graph * h + o
                    gv = dy[t, col] if st.src[t, col] == k else zero
                    gy[o] = gv if st.ypos[k, t, col] else gv * net.slope
                mean = zero
                for i in range(lo, hi):
                    acc = zero
                    for o in range(h):
                        acc += hk[t * n + i, o] * gy[o]
                    da[i] = acc
                    alpha = st.alpha[k, t, i]
                    mean += alpha * acc
                    for o in range(h):
                        dh[t * n + i, o] += alpha * gy[o]
                for i in range(lo, hi):
                    ds = st.alpha[k, t, i] * (da[i] - mean)
                    for o in range(h):
                        dh[t * n + i, o] += ds * net.att[k, o]

    @_jit
    def _edge_backward(net, st, k, t_n, dh):
        """(duv (T n, 2H), dc (T n, H)): ∂/∂[u v] through the ring edges (∂v = −∂c) and ∂c,
        given dh = ∂/∂h⁽ᵏ⁾."""
        n = st.idx.shape[1]
        h = net.att.shape[1]
        rows = t_n * n
        slope = net.slope
        dmsg = mm(dh, net.wl[k])
        a = np.empty((3 * rows, h), dh.dtype)
        top = st.mask[k, st.mask.shape[1] - 1]
        for t in range(t_n):
            base = 3 * n * t
            for e in range(3):
                for i in range(n):
                    r = base + e * n + i
                    for o in range(h):
                        gv = dmsg[t * n + i, o]
                        a[r, o] = gv if top[r, o] else gv * slope
        for layer in range(net.wh.shape[1] - 1, -1, -1):
            a = mm(a, net.wh[k, layer])
            m = st.mask[k, layer]
            for r in range(3 * rows):
                for o in range(h):  # a select, not a branch: vectorised
                    a[r, o] = a[r, o] if m[r, o] else a[r, o] * slope
        duv = np.zeros((rows, 2 * h), dh.dtype)
        dc = np.empty((rows, h), dh.dtype)
        for t in range(t_n):
            base = 3 * n * t
            for i in range(n):
                r = t * n + i
                jp = t * n + net.ring[0, i]
                jn = t * n + net.ring[1, i]
                for o in range(h):
                    gp = a[base + i, o]
                    gn = a[base + n + i, o]
                    dc[r, o] = gp + gn + a[base + 2 * n + i, o]
                    duv[r, h + o] -= dc[r, o]
                    duv[r, o] -= gp + gn
                    duv[jp, o] += gp
                    duv[jn, o] += gn
        return duv, dc

    @_jit
    def _cross_backward(net, st, k, t_n, two_way, duv, dc, dlphi, dnear, dscore):
        """Through c = Σ_c w_c v_{j_c}: ∂w, the softmax, ∂ℓ → dlphi, dnear (T, n, C) and,
        two-way, the partners' ∂v (into duv) and ∂s (dscore (T n,), layers k ≥ 1)."""
        n, cand = st.idx.shape[1], st.idx.shape[2]
        h = net.att.shape[1]
        zero = net.scale * 0
        w = st.w[k]
        dw = np.empty(cand, duv.dtype)
        for t in range(t_n):
            for i in range(n):
                r = t * n + i
                mean = zero
                for c in range(cand):
                    j = st.idx[t, i, c]
                    acc = zero
                    for o in range(h):
                        vj = st.v[k, t * n + j, o] if two_way else net.v[k, j, o]
                        acc += dc[r, o] * vj
                    dw[c] = acc
                    mean += w[t, i, c] * acc
                for c in range(cand):
                    dl = w[t, i, c] * (dw[c] - mean)
                    dlphi[t, i, c] += dl
                    dnear[t, i, c] -= dl / net.tau[k]
                    if two_way:
                        j = t * n + st.idx[t, i, c]
                        if k:
                            dscore[j] += dl
                        for o in range(h):
                            duv[j, h + o] += w[t, i, c] * dc[r, o]

    @_jit
    def _candidates_backward(net, st, t_n, n_r, dlphi, dnear, g_out):
        """g_out += ∂/∂x through log φ and d² = |x_robot − x_partner|² of every row's real
        candidates (two-way obstacle rows: to their robot partners)."""
        n, cand = st.idx.shape[1], st.idx.shape[2]
        m = net.xo.shape[0]
        for t in range(t_n):
            for i in range(n):
                real = min(cand, m if i < n_r else n_r)
                _log_phi_backward(st.near[t, i], dlphi[t, i], dnear[t, i], real)
                for c in range(real):
                    j = st.idx[t, i, c]
                    robot, partner = (i, j) if i < n_r else (j, i)
                    for e in range(2):
                        p = st.xu[t, partner, e] if n > n_r else net.xo[partner, e]
                        g_out[t, robot, e] += 2 * (st.xu[t, robot, e] - p) * dnear[t, i, c]

    @_jit
    def _backward_tile(x, net, st, g_out):
        """g_out (T, N_r, 2) ← ∂d̂/∂x of the tile (x normalised) from the forward's state."""
        t_n, n_r, _ = x.shape
        n, cand = st.idx.shape[1], st.idx.shape[2]
        layers, h = net.att.shape
        rows = t_n * n
        two_way = n > n_r
        gs = np.zeros((t_n, st.s.shape[1]), x.dtype)  # ∂d̂/∂s of the distance points
        dy = _head_backward(net, st, t_n, gs)  # (T, P)
        dh = np.zeros((rows, h), x.dtype)  # ∂/∂h⁽ᵏ⁾ from the layers above
        dlphi = np.zeros((t_n, n, cand), x.dtype)
        dnear = np.zeros((t_n, n, cand), x.dtype)
        dscore = np.zeros(rows, x.dtype)
        for k in range(layers - 1, -1, -1):
            _readout_backward(net, st, k, t_n, n_r, dy, dh)
            duv, dc = _edge_backward(net, st, k, t_n, dh)
            if net.din.shape[1]:  # c_i holds s_i w_k (one-way: robot rows only)
                for t in range(t_n):
                    for i in range(n):
                        acc = net.scale * 0
                        for o in range(h):
                            acc += dc[t * n + i, o] * net.din[k, o]
                        gs[t, i] += acc
            dscore[:] = 0
            _cross_backward(net, st, k, t_n, two_way, duv, dc, dlphi, dnear, dscore)
            for t in range(t_n):  # ∂x from z = (x ‖ h) (robot rows: obstacles are constants)
                for i in range(n_r):
                    for j in range(2):
                        acc = net.scale * 0
                        for o in range(2 * h):
                            acc += duv[t * n + i, o] * net.ax[k, j, o]
                        g_out[t, i, j] += acc
            if k:
                dh = mm(duv, net.aht[k])
                if two_way:  # the partner scores s = a_{k−1}ᵀ h⁽ᵏ⁻¹⁾
                    for r in range(rows):
                        for o in range(h):
                            dh[r, o] += dscore[r] * net.att[k - 1, o]
        _candidates_backward(net, st, t_n, n_r, dlphi, dnear, g_out)
        if gs.shape[1]:
            points_backward(net, gs, st.ds, g_out)
