"""The readout kernels of :mod:`.fused_net_kernels` (numba; the math is in :mod:`.fused_net`'s
docstring): per layer the attention readout of each graph, max-pooled over the layers
(:func:`_readout`), and the head MLP from the pooled readouts to d̂ (:func:`_head`, with the
soft minimum of :mod:`.fused_net_distances` for ``min_readout`` networks). Arrays travel as
:class:`~.fused_net_kernels.Net` and :class:`~.fused_net_kernels.State`.
"""

from __future__ import annotations

import numpy as np

from .fused import AVAILABLE

if AVAILABLE:
    from .fused import _jit, _leaky_rows
    from .fused_net_distances import readout as _distance_readout
    from .fused_net_distances import soft_min
    from .gemm import mm

    @_jit
    def _readout(net, st, k, t_n, n_r, pooled):
        """Per configuration and graph (robot rows, then two-way obstacle rows): α =
        softmax_i a_kᵀ h_i, y = σ(Σ α_i h_i); pooled (T, P) ← max over the layers so far."""
        n = st.idx.shape[1]
        h = net.att.shape[1]
        hk = st.h[k]
        y_sum = np.empty(h, hk.dtype)
        for t in range(t_n):
            for i in range(n):
                s = net.scale * 0
                for o in range(h):
                    s += hk[t * n + i, o] * net.att[k, o]
                st.logit[k, t, i] = s
            for graph in range(pooled.shape[1] // h):
                lo, hi = (0, n_r) if graph == 0 else (n_r, n)
                top = st.logit[k, t, lo]
                for i in range(lo, hi):
                    top = max(top, st.logit[k, t, i])
                total = net.scale * 0
                for i in range(lo, hi):
                    e = np.exp(st.logit[k, t, i] - top)
                    st.alpha[k, t, i] = e
                    total += e
                for i in range(lo, hi):
                    st.alpha[k, t, i] /= total
                for o in range(h):
                    y_sum[o] = 0
                for i in range(lo, hi):  # node by node: contiguous rows
                    alpha = st.alpha[k, t, i]
                    for o in range(h):
                        y_sum[o] += alpha * hk[t * n + i, o]
                for o in range(h):
                    y = y_sum[o]
                    col = graph * h + o
                    st.ypos[k, t, col] = y > 0
                    y = y if y > 0 else y * net.slope
                    if k == 0 or y > pooled[t, col]:
                        pooled[t, col] = y
                        st.src[t, col] = k

    @_jit
    def _head(net, st, pooled, d_out):
        """d_out (T,) ← d̂ of the tile's pooled readouts (T, P) (st.hmask ← the signs; with
        ``min_readout`` st.m, st.sw ← the soft minimum and its weights, st.y ← the MLP)."""
        t_n = pooled.shape[0]
        a = mm(pooled, net.h0t)  # the head (one-way: its obstacle half is in hb0)
        if net.hm.shape[0]:  # min_readout: the soft minimum is the head's last input
            for t in range(t_n):
                st.m[t] = soft_min(net, st.s[t], st.sw[t])
                for o in range(a.shape[1]):
                    a[t, o] += st.m[t] * net.hm[o]
        _leaky_rows(a, net.hb0, st.hmask[0], net.slope)
        for layer in range(net.hwt.shape[0]):
            a = mm(a, net.hwt[layer])
            _leaky_rows(a, net.hb[layer], st.hmask[layer + 1], net.slope)
        for t in range(t_n):
            out = net.blast[0]
            for o in range(a.shape[1]):
                out += a[t, o] * net.wlast[o]
            st.y[t] = out
            if net.hm.shape[0]:  # min_readout: d̂ = scale · (m + y), or banded
                d_out[t] = _distance_readout(net, st.m[t], out)[0]
            else:
                d_out[t] = out * net.scale
