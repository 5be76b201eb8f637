"""Nearest-node candidates and their soft weights, compiled (numba), for the planar and the
3-D whole-network passes (:mod:`.fused_net_kernels`, :mod:`..graphdistnet3d.fused3d_kernels`).

Each point p of a tile (T configurations × N nodes, D = 2 or 3 coordinates) gets its C
candidate partners: the C smallest (d², row) pairs among M partner nodes, ascending, with

    log φ_c = log max(d²_{C'} − d²_c, 10⁻¹²),   C' = min(C, M) the last real candidate,

slots beyond M padded (d² ``PAD_DIST2``, log φ ``NO_WEIGHT``: weight 0). The search runs point
parallel: partner by partner, one compare-and-swap pass per candidate slot over all the tile's
points, which the compiler vectorises (an insertion search per point branches on every pair).
The soft weights w_c = softmax_c(ℓ_c) of the logits ℓ run as flat passes over all the tile's
candidates (maximum, exponential, sum), so the exponentials vectorise too.
"""

from __future__ import annotations

import numpy as np

from .fused import AVAILABLE
from .geometry import PAD_DIST2

NO_WEIGHT = -1e30  # log φ of a padded candidate: weight exp(−1e30) = 0 (finite: fastmath)

if AVAILABLE:
    from .fused import _jit

    @_jit
    def point_candidates(x, partners, offset, idx, near, lphi):
        """idx (+ ``offset``), near (d²), lphi (T, N, C) of the points x (T, N, D) among
        partners (M, D) (module docstring)."""
        t_n, n, dims = x.shape
        cand, p = idx.shape[2], t_n * n
        real = min(cand, partners.shape[0])
        pts = np.empty((dims, p), x.dtype)  # coordinate-major: contiguous over the points
        for t in range(t_n):
            for i in range(n):
                for d in range(dims):
                    pts[d, t * n + i] = x[t, i, d]
        best = np.empty((real, p), x.dtype)  # each point's candidates so far, ascending
        which = np.zeros((real, p), np.int32)  # their partner rows (int32: wider vectors)
        best[:] = PAD_DIST2
        dd, jj = np.empty(p, x.dtype), np.empty(p, np.int32)  # the pair moving down the slots
        for j in range(partners.shape[0]):
            dd[:] = 0
            for d in range(dims):
                o = partners[j, d]
                for q in range(p):
                    dd[q] += (pts[d, q] - o) ** 2
            jj[:] = j
            for c in range(real):
                _slot(best[c], which[c], dd, jj)
        for t in range(t_n):
            for i in range(n):
                q = t * n + i
                for c in range(cand):
                    if c < real:
                        near[t, i, c], idx[t, i, c] = best[c, q], offset + which[c, q]
                        lphi[t, i, c] = np.log(max(best[real - 1, q] - best[c, q], 1e-12))
                    else:
                        near[t, i, c], idx[t, i, c], lphi[t, i, c] = PAD_DIST2, offset, NO_WEIGHT

    @_jit
    def _slot(best, which, dd, jj):
        """One candidate slot over all points: keep the smaller (d², row) of the slot's and
        the moving pair's, pass the larger on."""
        for q in range(best.shape[0]):
            old, row, new, new_row = best[q], which[q], dd[q], jj[q]
            swap = (new < old) | ((new == old) & (new_row < row))
            best[q] = new if swap else old
            which[q] = new_row if swap else row
            dd[q] = old if swap else new
            jj[q] = row if swap else new_row

    @_jit
    def softmax_groups(w, cand):
        """w (R C,) ← the softmax of each group of ``cand`` consecutive entries, in place."""
        for r in range(0, w.shape[0], cand):
            top = w[r]
            for c in range(1, cand):
                top = max(top, w[r + c])
            for c in range(cand):
                w[r + c] -= top
        for q in range(w.shape[0]):
            w[q] = np.exp(w[q])
        for r in range(0, w.shape[0], cand):
            total = w[r]
            for c in range(1, cand):
                total += w[r + c]
            for c in range(cand):
                w[r + c] /= total
