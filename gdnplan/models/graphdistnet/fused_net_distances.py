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
∂d̂/∂y = scale g, ∂d̂/∂m (direct) = scale (1 − g + (y − m) g'), g' = −8 scale / β · g (1 − g).
"""

from __future__ import annotations

import numpy as np

from .fused import AVAILABLE
from .geometry import PAD_DIST2

if AVAILABLE:
    from .fused import _jit

    @_jit
    def _ring_distance(p0, p1, xo, onext):
        """(s, ∂s/∂p0, ∂s/∂p1) of the point (p0, p1) to the rings xo (M, 2), onext (M,)."""
        best, bx, by = PAD_DIST2 + p0 * 0, p0 * 0, p0 * 0
        winding = 0
        for m in range(xo.shape[0]):
            ax, ay = xo[m, 0], xo[m, 1]
            ex, ey = xo[onext[m], 0] - ax, xo[onext[m], 1] - ay
            wx, wy = p0 - ax, p1 - ay
            t = (wx * ex + wy * ey) / max(ex * ex + ey * ey, 1e-12)
            t = min(max(t, 0.0), 1.0)
            rx, ry = wx - t * ex, wy - t * ey
            d2 = rx * rx + ry * ry
            if d2 < best:
                best, bx, by = d2, rx, ry
            left = ex * wy - ey * wx
            if wy >= 0 and wy < ey and left > 0:
                winding += 1
            elif wy < 0 and wy >= ey and left < 0:
                winding -= 1
        sign = -1.0 if winding != 0 else 1.0
        if best < 1e-12:  # sqrt(clamp(δ², 1e-12)): no gradient below the floor
            return sign * 1e-6, p0 * 0, p0 * 0
        dist = np.sqrt(best)
        return sign * dist, sign * bx / dist, sign * by / dist

    @_jit
    def tile_distances(x, net, s, ds):
        """s (T, P), ds (T, P, 2) ← the signed distances of the tile's points (nodes, then
        probes) and their gradients by the point's coordinates."""
        t_n, n_r, _ = x.shape
        split = net.probe
        for t in range(t_n):
            for i in range(n_r):
                for j in range(split):
                    f = j / split
                    nx = net.ring[1, i]
                    p0 = x[t, i, 0] + f * (x[t, nx, 0] - x[t, i, 0])
                    p1 = x[t, i, 1] + f * (x[t, nx, 1] - x[t, i, 1])
                    col = i if j == 0 else n_r + i * (split - 1) + j - 1
                    s[t, col], ds[t, col, 0], ds[t, col, 1] = _ring_distance(
                        p0, p1, net.xo, net.onext
                    )

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
        dg = -8 * scale / net.band * g * (1 - g)
        return scale * (m + g * (y - m)), scale * g, scale * (1 - g + (y - m) * dg)

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
