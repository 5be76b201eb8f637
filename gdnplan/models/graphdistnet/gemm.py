"""The matrix products of the compiled kernels: the BLAS that torch carries, called from numba.

Every product of the fused passes (:mod:`.fused`, :mod:`.fused_net`, the 3-D
:mod:`~gdnplan.models.graphdistnet3d.fused3d`) is a small one: a tile of R rows (a few
thousand) times an H × H weight (H = 32),

    C (R, N) = A (R, K) · B (K, N),   row-major, float32 or float64.

numba's own :func:`numpy.dot` calls scipy's OpenBLAS, whose kernels for K = N = 32 run at a
fraction of the machine's peak on some CPUs; torch's CPU wheel carries a BLAS of its own (MKL
on x86-64) whose ``sgemm_`` / ``dgemm_`` it exports. :func:`mm` calls that Fortran routine on
the transposed problem (row-major C is column-major Cᵀ = Bᵀ Aᵀ, so no copy), on the calling
thread only (MKL's thread-local count is set to 1 around the call and restored). The routine
is reached through two process-wide symbols, ``gdnplan_sgemm`` and ``gdnplan_dgemm``, so the
kernels' machine code cached on disk stays valid whichever routine the symbols point to:

* torch's ``sgemm_`` / ``dgemm_`` when its library exports them and they pass a check
  against numpy on a small product at import (:data:`BACKEND` says which);
* else compiled fallbacks with the same signature that call :func:`numpy.dot` (the products
  as before this module).

The comparison that chose this: benchmarks/gemm.py and docs/decisions.md (2026-12-03).
"""

from __future__ import annotations

import ctypes
from pathlib import Path

import numpy as np
import torch

from ...errors import numba_environment_error

try:
    import numba
    from llvmlite import binding
    from numba import types
except ImportError:  # the fused kernels are off without numba (fused.AVAILABLE)
    numba = None
except ValueError as e:  # numba refuses its environment at import (NUMBA_NUM_THREADS=0)
    raise numba_environment_error(e) from e

__all__ = ["BACKEND", "mm"]

BACKEND = "none (numba missing)"
_N = 78  # ord("N"): no transpose


def _torch_blas() -> ctypes.CDLL | None:
    """torch's CPU library when it exports the Fortran gemm routines, else None."""
    paths = sorted((Path(torch.__file__).parent / "lib").glob("*torch_cpu.*"))  # .so/.dylib/.dll
    try:
        lib = ctypes.CDLL(str(paths[0]))
        lib.sgemm_, lib.dgemm_  # noqa: B018  (AttributeError when not exported)
    except (IndexError, OSError, AttributeError):
        return None
    return lib


def _address(function) -> int:
    return ctypes.cast(function, ctypes.c_void_p).value


def _agrees(lib: ctypes.CDLL) -> bool:
    """Whether ``lib``'s sgemm_ and dgemm_ (called through ctypes as :func:`mm` calls them)
    match numpy on small products."""
    rng = np.random.default_rng(0)
    for routine, dtype, tol in ((lib.sgemm_, np.float32, 1e-4), (lib.dgemm_, np.float64, 1e-12)):
        a, b = rng.normal(size=(37, 32)).astype(dtype), rng.normal(size=(32, 33)).astype(dtype)
        out = np.zeros((37, 33), dtype)
        ints = [ctypes.c_int32(v) for v in (33, 37, 32, 33, 32, 33)]
        one, zero = (np.array([v], dtype) for v in (1, 0))
        no = ctypes.c_char(b"N")
        routine(ctypes.byref(no), ctypes.byref(no), *map(ctypes.byref, ints[:3]),
                one.ctypes.data_as(ctypes.c_void_p), b.ctypes.data_as(ctypes.c_void_p),
                ctypes.byref(ints[3]), a.ctypes.data_as(ctypes.c_void_p), ctypes.byref(ints[4]),
                zero.ctypes.data_as(ctypes.c_void_p), out.ctypes.data_as(ctypes.c_void_p),
                ctypes.byref(ints[5]))  # fmt: skip
        if not np.allclose(out, a @ b, rtol=tol, atol=tol):
            return False
    return True


if numba is not None:
    _GEMM = types.void(*([types.voidptr] * 13))  # Fortran ?gemm: every argument by reference
    _THREADS = types.intc(types.intc)  # MKL_Set_Num_Threads_Local(n) by value -> previous

    def _fallback(dtype):
        @numba.cfunc(_GEMM, cache=True)
        def gemm(ta, tb, m, n, k, alpha, a, lda, b, ldb, beta, c, ldc):
            """Cᵀ = Bᵀ Aᵀ row-major (what :func:`mm` asks for: no transposes, alpha 1, beta 0)."""
            mm_, nn, kk = numba.carray(m, 1, np.int32)[0], numba.carray(n, 1, np.int32)[0], \
                numba.carray(k, 1, np.int32)[0]  # fmt: skip
            la, lb = numba.carray(lda, 1, np.int32)[0], numba.carray(ldb, 1, np.int32)[0]
            lc = numba.carray(ldc, 1, np.int32)[0]
            at = np.ascontiguousarray(numba.carray(a, (kk, la), dtype)[:, :mm_])
            bt = np.ascontiguousarray(numba.carray(b, (nn, lb), dtype)[:, :kk])
            numba.carray(c, (nn, lc), dtype)[:, :mm_] = np.dot(bt, at)

        return gemm

    def _no_threads():
        @numba.cfunc(_THREADS, cache=True)
        def none(n):
            return 0

        return none

    _KEPT: list = []  # the fallbacks in use: their code must live as long as the symbols

    def _register(lib: ctypes.CDLL | None) -> None:
        """Point the kernels' symbols at ``lib``'s routines (None: the numpy fallbacks, compiled
        only then)."""
        threads = getattr(lib, "MKL_Set_Num_Threads_Local", None) if lib else None
        if lib is None:
            _KEPT.extend((_fallback(np.float32), _fallback(np.float64)))
        if threads is None:
            _KEPT.append(_no_threads())
        binding.add_symbol("gdnplan_sgemm", _address(lib.sgemm_) if lib else _KEPT[0].address)
        binding.add_symbol("gdnplan_dgemm", _address(lib.dgemm_) if lib else _KEPT[1].address)
        count = _address(threads) if threads else _KEPT[-1].address
        binding.add_symbol("gdnplan_blas_threads", count)

    _sgemm = types.ExternalFunction("gdnplan_sgemm", _GEMM)
    _dgemm = types.ExternalFunction("gdnplan_dgemm", _GEMM)
    _set_threads = types.ExternalFunction("gdnplan_blas_threads", _THREADS)

    @numba.njit(cache=True, fastmath=True, nogil=True)
    def mm(a, b):
        """a (R, K) · b (K, N) -> (R, N), a new C-ordered array of a's dtype (float32 or
        float64, b the same), on the calling thread."""
        a = np.ascontiguousarray(a)
        b = np.ascontiguousarray(b)
        r, k = a.shape
        n = b.shape[1]
        out = np.empty((r, n), a.dtype)
        if r == 0 or n == 0:
            return out
        if k == 0:
            out[:] = 0
            return out
        dims = np.array([n, r, k, n, k, n], np.int32)  # m n k lda ldb ldc of Cᵀ = Bᵀ Aᵀ
        no = np.full(1, _N, np.uint8)
        scalars = np.array([1, 0], a.dtype)  # alpha, beta
        previous = _set_threads(1)
        args = (no.ctypes.data, no.ctypes.data, dims[0:].ctypes.data, dims[1:].ctypes.data,
                dims[2:].ctypes.data, scalars[0:].ctypes.data, b.ctypes.data,
                dims[3:].ctypes.data, a.ctypes.data, dims[4:].ctypes.data,
                scalars[1:].ctypes.data, out.ctypes.data, dims[5:].ctypes.data)  # fmt: skip
        if a.itemsize == 4:
            _sgemm(*args)
        else:
            _dgemm(*args)
        _set_threads(previous)
        return out

    _lib = _torch_blas()
    if _lib is not None and _agrees(_lib):
        _register(_lib)
        BACKEND = f"torch's BLAS ({Path(_lib._name).name}: sgemm_, dgemm_)"
    else:
        _register(None)
        BACKEND = "numpy.dot (scipy's BLAS)"
