"""The fused ring messages of GraphDistNet's lean path: numba kernels, tile by tile in cache.

The function of :class:`~.layers._LeakyRingMessages`: for every node i of a batch (B, N) and
its edges e ∈ (prev, next, self),

    pre_e = u_{j_e} − u_i + c_i (ring edges),  pre_self = c_i,
    m_i = Σ_e g(pre_e),  g = σ ∘ L_m ∘ σ ∘ … ∘ L_1 ∘ σ,  σ = LeakyReLU(0.2),

L_l the hidden linear layers (W_l, b_l) of h_k (all of width H). The reference path builds
every (B, 3, N, H) activation in memory, one library call per element-wise pass. Here a tile
of configurations (``TILE_ROWS`` edge rows, half a megabyte: in L2 cache) goes
through the whole edge MLP at once: the message build, each product (a BLAS sgemm on the
tile, :func:`numpy.dot` inside numba), the bias and σ written as loops over the tile, the sum
over the edges. The backward pass keeps only the signs of the pre-activations (σ'(s) = 1 for
s > 0, else 0.2; one byte per activation) and runs tile by tile as well:

    ∂/∂s_m = σ'(s_m) ⊙ ∂m,  ∂/∂s_{l−1} = σ'(s_{l−1}) ⊙ (∂/∂s_l) W_l,
    ∂u_j = Σ_{(i,e): j_e = j} ∂pre_e − Σ_{e ring} ∂pre_{e,i} [j = i],  ∂c_i = Σ_e ∂pre_{e,i}.

Gradients flow to u and c only (inference: the weights get none). The kernels are compiled on
first use and cached on disk (``cache=True``); :data:`AVAILABLE` is False without numba, and
:func:`supports` says which networks the kernel serves (hidden layers of one width).
"""

from __future__ import annotations

import contextlib
import functools
from collections.abc import Iterator

import numpy as np
import torch

from ...errors import numba_environment_error
from .layers import LEAKY_SLOPE

try:
    import numba
    import scipy.linalg.cython_blas  # noqa: F401  numba's numpy.dot calls this BLAS
    from threadpoolctl import ThreadpoolController
except ImportError:  # the reference path serves (GraphDistNetModel's default)
    numba = None
except ValueError as e:  # numba refuses its environment at import (NUMBA_NUM_THREADS=0)
    raise numba_environment_error(e) from e

AVAILABLE = numba is not None
TILE_ROWS = 4096  # edge rows per tile (3 N per configuration): 512 kB per buffer, in L2
# (larger tiles keep sgemm efficient; docs/decisions.md#fused-kernels)

__all__ = ["AVAILABLE", "TILE_ROWS", "FusedRingMessages", "SparseMix", "supports"]


def supports(mlp: tuple[int, ...]) -> bool:
    """Whether the fused kernel serves edge MLPs of hidden widths ``mlp`` (h_k's ``mlp``):
    at least two hidden widths (one hidden linear layer), all equal."""
    return AVAILABLE and len(mlp) >= 2 and len(set(mlp)) == 1


@functools.cache
def _blas_libraries() -> list:
    """threadpoolctl's controllers of the loaded BLAS libraries (scipy's: numba's dot)."""
    return ThreadpoolController().select(user_api="blas").lib_controllers


@contextlib.contextmanager
def _serial_blas() -> Iterator[None]:
    """The BLAS libraries on one thread inside: the kernels' products are small (one tile),
    and a BLAS thread pool waiting on a busy core costs far more than it gains
    (docs/decisions.md#fused-kernels); the caller's counts are restored after."""
    libraries = _blas_libraries()
    counts = [lib.num_threads for lib in libraries]
    for lib in libraries:
        lib.set_num_threads(1)
    try:
        yield
    finally:
        for lib, count in zip(libraries, counts, strict=True):
            lib.set_num_threads(count)


def _tile(n: int) -> int:
    """Configurations per tile for N nodes per configuration."""
    return max(1, TILE_ROWS // (3 * n))


if AVAILABLE:
    from .kernel_cache import purge_stale

    purge_stale()  # before any cached kernel loads: numba keys its cache on one file only
    from .gemm import mm

    _jit = numba.njit(cache=True, fastmath=True, nogil=True)

    @_jit
    def _log_phi_backward(near, dlphi, dnear, real):
        """dnear (C,) += ∂/∂d² of Σ_c dlphi_c log φ_c, φ_c = d²_{real−1} − d²_c, over one
        node's first ``real`` candidates (φ floored at 1e-12 has no gradient)."""
        last = near[real - 1]
        for c in range(real - 1):
            delta = last - near[c]
            if delta >= 1e-12:
                q = dlphi[c] / delta
                dnear[real - 1] += q
                dnear[c] -= q

    @_jit
    def _leaky_rows(a, bias, mask, slope):
        """a ← σ(a + bias) row by row (a (R, H), bias (H,) or empty); mask ← a > 0 (or skip)."""
        rows, h = a.shape
        keep = mask.shape[0] > 0
        has_bias = bias.shape[0] > 0
        for r in range(rows):
            for o in range(h):
                s = a[r, o] + bias[o] if has_bias else a[r, o]
                pos = s > 0
                a[r, o] = s if pos else s * slope
                if keep:
                    mask[r, o] = pos

    @_jit
    def _forward(u, c, ring, wt, b, out, masks, slope, tb):
        """out (B, N, H) ← Σ_e g(pre_e); masks (L + 1, B·3·N, H) ← signs (or shape (0, 0, 0))."""
        bsz, n, h = u.shape
        layers = wt.shape[0]
        keep = masks.shape[0] > 0
        buf = np.empty((tb * 3 * n, h), u.dtype)
        empty = np.empty(0, u.dtype)
        nomask = np.empty((0, h), np.bool_)
        for b0 in range(0, bsz, tb):
            nb = min(tb, bsz - b0)
            rows = nb * 3 * n
            a = buf[:rows]
            for t in range(nb):
                base = t * 3 * n
                for i in range(n):
                    jp = ring[i]
                    jn = ring[n + i]
                    for o in range(h):
                        ci = c[b0 + t, i, o] - u[b0 + t, i, o]
                        a[base + i, o] = u[b0 + t, jp, o] + ci
                        a[base + n + i, o] = u[b0 + t, jn, o] + ci
                        a[base + 2 * n + i, o] = c[b0 + t, i, o]
            r0 = b0 * 3 * n
            _leaky_rows(a, empty, masks[0, r0 : r0 + rows] if keep else nomask, slope)
            for layer in range(layers):
                a = mm(a, wt[layer])
                m = masks[layer + 1, r0 : r0 + rows] if keep else nomask
                _leaky_rows(a, b[layer], m, slope)
            for t in range(nb):
                base = t * 3 * n
                for i in range(n):
                    for o in range(h):
                        out[b0 + t, i, o] = (
                            a[base + i, o] + a[base + n + i, o] + a[base + 2 * n + i, o]
                        )

    @_jit
    def _backward(grad, ring, w, masks, du, dc, slope, tb):
        """du, dc (B, N, H) ← ∂/∂u, ∂/∂c of Σ_e g(pre_e) given ∂/∂m = grad (B, N, H)."""
        bsz, n, h = grad.shape
        layers = w.shape[0]
        g = np.empty((tb * 3 * n, h), grad.dtype)
        for b0 in range(0, bsz, tb):
            nb = min(tb, bsz - b0)
            rows = nb * 3 * n
            r0 = b0 * 3 * n
            top = masks[layers, r0 : r0 + rows]
            a = g[:rows]
            for t in range(nb):
                base = t * 3 * n
                for e in range(3):
                    for i in range(n):
                        r = base + e * n + i
                        for o in range(h):
                            x = grad[b0 + t, i, o]
                            a[r, o] = x if top[r, o] else x * slope
            for layer in range(layers - 1, -1, -1):
                a = mm(a, w[layer])
                m = masks[layer, r0 : r0 + rows]
                for r in range(rows):
                    for o in range(h):
                        if not m[r, o]:
                            a[r, o] *= slope
            for t in range(nb):
                base = t * 3 * n
                bb = b0 + t
                for i in range(n):
                    jp = ring[i]
                    jn = ring[n + i]
                    for o in range(h):
                        gp = a[base + i, o]
                        gn = a[base + n + i, o]
                        dc[bb, i, o] = gp + gn + a[base + 2 * n + i, o]
                        du[bb, i, o] -= gp + gn
                        du[bb, jp, o] += gp
                        du[bb, jn, o] += gn


if AVAILABLE:

    @_jit
    def _mix_forward(w, idx, v, out):
        """out[b, i] ← Σ_c w[b, i, c] v[idx[b, i, c]] (w, idx (B, n, C); v (M, H))."""
        bsz, n, cand = w.shape
        h = v.shape[1]
        for b in range(bsz):
            for i in range(n):
                for o in range(h):
                    out[b, i, o] = 0
                for k in range(cand):
                    wk = w[b, i, k]
                    j = idx[b, i, k]
                    for o in range(h):
                        out[b, i, o] += wk * v[j, o]

    @_jit
    def _mix_backward(grad, idx, v, dw):
        """dw[b, i, c] ← grad[b, i] · v[idx[b, i, c]]."""
        bsz, n, cand = idx.shape
        h = v.shape[1]
        for b in range(bsz):
            for i in range(n):
                for k in range(cand):
                    j = idx[b, i, k]
                    acc = grad[b, i, 0] * v[j, 0]
                    for o in range(1, h):
                        acc += grad[b, i, o] * v[j, o]
                    dw[b, i, k] = acc


class SparseMix(torch.autograd.Function):
    """v̄_i = Σ_c w_ic v_{j_c} (B, n, H) for weights w (B, n, C), candidates idx (B, n, C)
    (rows of v) and constant partner terms v (M, H) (one-way networks: the scene's obstacle
    features): the cross terms without the dense (B, n, M) weights of
    :func:`~.lean._cross_mix`. Gradients flow to w only: ∂w_ic = ∂v̄_i · v_{j_c}."""

    @staticmethod
    def forward(ctx, w: torch.Tensor, idx: torch.Tensor, v: torch.Tensor) -> torch.Tensor:
        w_np = w.detach().contiguous().numpy()
        idx_np = idx.contiguous().numpy()
        v_np = v.detach().contiguous().numpy()
        out = np.empty((*w_np.shape[:2], v_np.shape[1]), w_np.dtype)
        _mix_forward(w_np, idx_np, v_np, out)
        ctx.mix = (idx_np, v_np)
        return torch.from_numpy(out)

    @staticmethod
    def backward(ctx, grad: torch.Tensor):
        idx_np, v_np = ctx.mix
        dw = np.empty(idx_np.shape, v_np.dtype)
        _mix_backward(grad.detach().contiguous().numpy(), idx_np, v_np, dw)
        return torch.from_numpy(dw), None, None


def _weights(weights: tuple[torch.Tensor, ...]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(W_lᵀ (L, H, H), W_l (L, H, H), b_l (L, H)) numpy arrays of the hidden layers."""
    w = torch.stack(weights[::2]).detach()
    b = torch.stack(weights[1::2]).detach()
    return w.transpose(1, 2).contiguous().numpy(), w.contiguous().numpy(), b.numpy()


class FusedRingMessages(torch.autograd.Function):
    """:class:`~.layers._LeakyRingMessages` by the fused kernels (module docstring): the same
    arguments (u, c (B, N, H) float32 or float64 on CPU, ring (2 N,), the hidden layers' W and
    b, of u's dtype) and result (B, N, H)."""

    @staticmethod
    def forward(ctx, u: torch.Tensor, c: torch.Tensor, ring: torch.Tensor, *weights: torch.Tensor):
        wt, w, b = _weights(weights)
        u_np = u.detach().contiguous().numpy()
        c_np = c.detach().contiguous().numpy()
        ring_np = ring.numpy()
        bsz, n, h = u_np.shape
        out = np.empty_like(u_np)
        keep = any(ctx.needs_input_grad[:2])
        shape = (len(wt) + 1, bsz * 3 * n, h) if keep else (0, 0, h)
        masks = np.empty(shape, np.bool_)
        slope = u_np.dtype.type(LEAKY_SLOPE)
        with _serial_blas():
            _forward(u_np, c_np, ring_np, wt, b, out, masks, slope, _tile(n))
        if keep:
            ctx.fused = (ring_np, w, masks)
        return torch.from_numpy(out)

    @staticmethod
    def backward(ctx, grad: torch.Tensor):
        ring_np, w, masks = ctx.fused
        g = grad.detach().contiguous().numpy()
        du = np.zeros_like(g)
        dc = np.empty_like(g)
        with _serial_blas():
            _backward(g, ring_np, w, masks, du, dc, g.dtype.type(LEAKY_SLOPE), _tile(g.shape[1]))
        rest = (None for _ in ctx.needs_input_grad[3:])
        return (torch.from_numpy(du), torch.from_numpy(dc), None, *rest)
