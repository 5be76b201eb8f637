"""The distance-aware parts of :mod:`.fused_net` (numba): node and probe-point distances, the
soft minimum and its band, forward and backward on one tile.

For one-way networks with ``node_distance`` every robot node i gets its signed distance s_i
to the obstacle rings (:func:`~.geometry.signed_ring_distance`, normalised units):

    δ_m = |p − a_m − t e_m|,  t = clamp((p − a_m)·e_m / |e_m|², 0, 1),  s = ± min_m δ_m,

negative where the winding number around p is non-zero, and ∂s/∂p = ± (p − a − t e) / δ of
the nearest edge (the gradient of a minimum is its minimiser's; (p − a − t e) ⊥ e, so t's
own derivative drops out). ``probe_split`` q adds the points p_i,j = x_i + (j/q)(x_next(i) −
x_i), j = 1 … q − 1, whose gradients go back to both ends: (1 − j/q) to x_i, j/q to x_next(i).
The point list of a configuration is the N_r nodes, then the probes node by node (P = q N_r).

``min_readout``: m = −τ_m log Σ_p exp(−s_p / τ_m) (∂m/∂s_p = softmax_p(−s/τ_m)) joins the
head's first layer (its column ``hm``), and d̂ = scale · (m + y) for the head's output y, or
with ``correction_band`` β: d̂ = scale · (m + g (y − m)), g = σ(8 (1 − scale · m / β)),
∂d̂/∂y = scale g, ∂d̂/∂m (direct) = scale (1 − g + (y − m) g'), g' = −8 scale / β · g (1 − g);
below g = :data:`GATE_FLOOR` the head passes no gradient (∂d̂/∂y = 0, ∂d̂/∂m = scale).
"""

from __future__ import annotations

import numpy as np

from .fused import AVAILABLE
from .geometry import PAD_DIST2

GATE_FLOOR = 1e-12  # a band gate g below this passes no gradient through the head: far from
# contact g ≈ exp(−8 scale m / β) underflows, and products of denormal floats are ~100× slower

if AVAILABLE:
    from .fused import _jit

    @_jit
    def _ring_distances(px, py, xo, onext, s, gx, gy):
        """s, gx, gy (n,) ← the signed distances of the points (px, py) (n,) to the rings xo
        (M, 2), onext (M,), and their gradients. Edge by edge over all points (contiguous: the
        inner loop vectorises): the smallest δ², its edge and the winding number; then the
        nearest edge's offset again per point."""
        n = px.shape[0]
        zero = px[0] * 0 if n else xo[0, 0] * 0  # constants of the dtype (literals promote)
        one = zero + 1
        best = np.full(n, zero + PAD_DIST2)
        arg = np.zeros(n, np.int64)
        winding = np.zeros(n, np.int64)
        for m in range(xo.shape[0]):
            ax, ay, by = xo[m, 0], xo[m, 1], xo[onext[m], 1]
            ex, ey = xo[onext[m], 0] - ax, by - ay
            inv = one / max(ex * ex + ey * ey, zero + 1e-12)
            for p in range(n):
                wx, wy = px[p] - ax, py[p] - ay
                t = min(max((wx * ex + wy * ey) * inv, zero), one)
                rx, ry = wx - t * ex, wy - t * ey
                d2 = rx * rx + ry * ry
                closer = d2 < best[p]
                best[p] = d2 if closer else best[p]
                arg[p] = m if closer else arg[p]
                left = ex * wy - ey * wx  # a_y ≤ p_y < b_y by the coordinates themselves
                up = (ay <= py[p]) & (py[p] < by) & (left > zero)
                down = (by <= py[p]) & (py[p] < ay) & (left < zero)
                winding[p] += np.int64(up) - np.int64(down)
        for p in range(n):
            m = arg[p]
            sign = -one if winding[p] != 0 else one
            if best[p] < 1e-12:  # sqrt(clamp(δ², 1e-12)): no gradient below the floor
                s[p], gx[p], gy[p] = sign * (one * 1e-6), zero, zero
                continue
            ax, ay = xo[m, 0], xo[m, 1]
            ex, ey = xo[onext[m], 0] - ax, xo[onext[m], 1] - ay
            wx, wy = px[p] - ax, py[p] - ay
            t = min(max((wx * ex + wy * ey) / max(ex * ex + ey * ey, zero + 1e-12), zero), one)
            dist = np.sqrt(best[p])
            s[p] = sign * dist
            gx[p] = sign * (wx - t * ex) / dist
            gy[p] = sign * (wy - t * ey) / dist

    @_jit
    def tile_distances(x, net, s, ds):
        """s (T, P), ds (T, P, 2) ← the signed distances of the tile's points (nodes, then
        probes) and their gradients by the point's coordinates."""
        t_n, n_r, _ = x.shape
        split = net.probe
        cols = n_r * split
        px = np.empty(t_n * cols, x.dtype)
        py = np.empty(t_n * cols, x.dtype)
        for t in range(t_n):
            for i in range(n_r):
                nx = net.ring[1, i]
                for j in range(split):
                    f = j / split
                    col = t * cols + (i if j == 0 else n_r + i * (split - 1) + j - 1)
                    px[col] = x[t, i, 0] + f * (x[t, nx, 0] - x[t, i, 0])
                    py[col] = x[t, i, 1] + f * (x[t, nx, 1] - x[t, i, 1])
        flat = s[:t_n].reshape(-1)  # (T P) views of the outputs
        gx = np.empty(t_n * cols, x.dtype)
        gy = np.empty(t_n * cols, x.dtype)
        _ring_distances(px, py, net.xo, net.onext, flat, gx, gy)
        for t in range(t_n):
            for c in range(cols):
                ds[t, c, 0] = gx[t * cols + c]
                ds[t, c, 1] = gy[t * cols + c]

    @_jit
    def soft_min(net, s, weights):
        """m of one configuration's distances s (P,); weights (P,) ← ∂m/∂s."""
        tau = net.tau_min
        low = s[0]
        for p in range(s.shape[0]):
            low = min(low, s[p])
        total = tau * 0
        for p in range(s.shape[0]):
            e = np.exp(-(s[p] - low) / tau)
            weights[p] = e
            total += e
        for p in range(s.shape[0]):
            weights[p] /= total
        return low - tau * np.log(total)

    @_jit
    def readout(net, m, y):
        """(d̂, ∂d̂/∂y, ∂d̂/∂m direct) of the soft minimum m and the head's output y."""
        scale = net.scale
        if net.band <= 0:
            return scale * (m + y), scale, scale
        g = 1 / (1 + np.exp(-8 * (1 - scale * m / net.band)))
        d = scale * (m + g * (y - m))
        if g < GATE_FLOOR:  # the head's gradient would be denormal: 0 (and the backward fast)
            return d, scale * 0, scale
        dg = -8 * scale / net.band * g * (1 - g)
        return d, scale * g, scale * (1 - g + (y - m) * dg)

    @_jit
    def points_backward(net, gs, ds, g_out):
        """g_out (T, N_r, 2) += the points' ∂d̂/∂s gs (T, P) through ds (T, P, 2)."""
        t_n, n_r, _ = g_out.shape
        split = net.probe
        for t in range(t_n):
            for i in range(n_r):
                nx = net.ring[1, i]
                for j in range(split):
                    f = j / split
                    col = i if j == 0 else n_r + i * (split - 1) + j - 1
                    for e in range(2):
                        gp = gs[t, col] * ds[t, col, e]
                        g_out[t, i, e] += (1 - f) * gp
                        if j:
                            g_out[t, nx, e] += f * gp
