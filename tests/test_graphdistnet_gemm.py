"""gdnplan.models.graphdistnet.gemm: the kernels' products against numpy, on both routines."""

from __future__ import annotations

import subprocess
import sys
import textwrap

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from gdnplan.models.graphdistnet import fused, gemm

pytestmark = pytest.mark.skipif(not fused.AVAILABLE, reason="numba missing")

TOLERANCE = {np.float32: 1e-5, np.float64: 1e-12}


def _check(a: np.ndarray, b: np.ndarray) -> None:
    out = gemm.mm(a, b)
    want = a.astype(np.float64) @ b.astype(np.float64)
    assert out.shape == want.shape and out.dtype == a.dtype and out.flags.c_contiguous
    scale = max(1.0, float(np.abs(a).max(initial=0) * np.abs(b).max(initial=0) * a.shape[1]))
    np.testing.assert_allclose(out, want, rtol=0, atol=TOLERANCE[a.dtype.type] * scale)


@settings(max_examples=60, deadline=None)
@given(
    r=st.integers(0, 300),
    k=st.integers(0, 40),
    n=st.integers(0, 70),
    dtype=st.sampled_from([np.float32, np.float64]),
    layout=st.sampled_from(["C", "F", "strided"]),
    seed=st.integers(0, 2**31 - 1),
)
def test_products_equal_numpy_for_any_shape_dtype_and_layout(r, k, n, dtype, layout, seed):
    rng = np.random.default_rng(seed)
    a = rng.normal(size=(r, 2 * k if layout == "strided" else k)).astype(dtype)
    b = rng.normal(size=(k, n)).astype(dtype)
    if layout == "strided":
        a = a[:, ::2]
    elif layout == "F":
        a, b = np.asfortranarray(a), np.asfortranarray(b)
    _check(a, b)


def test_kernel_sized_products_leave_their_inputs_alone():
    rng = np.random.default_rng(1)
    a, w = rng.normal(size=(2016, 32)).astype(np.float32), rng.normal(size=(32, 32))
    w = w.astype(np.float32)
    a0, w0 = a.copy(), w.copy()
    _check(a, w)
    assert np.array_equal(a, a0) and np.array_equal(w, w0)


def test_backend_is_named():
    assert gemm.BACKEND.startswith(("torch's BLAS", "numpy.dot"))


def test_without_torchs_blas_the_numpy_fallback_serves_the_same_products():
    """A process where torch's library cannot be opened: the symbols point at the fallbacks,
    and the kernels (cached on disk with the other routine) still compute the right values."""
    script = textwrap.dedent(
        """
        import ctypes
        real = ctypes.CDLL
        def refuse(name, *args, **kwargs):
            if "libtorch_cpu" in str(name):
                raise OSError("no torch BLAS in this test")
            return real(name, *args, **kwargs)
        ctypes.CDLL = refuse
        import numpy as np
        from gdnplan.models.graphdistnet import gemm
        ctypes.CDLL = real
        assert gemm.BACKEND.startswith("numpy.dot"), gemm.BACKEND
        rng = np.random.default_rng(2)
        for dtype in (np.float32, np.float64):
            a, b = rng.normal(size=(50, 32)).astype(dtype), rng.normal(size=(32, 7)).astype(dtype)
            assert np.allclose(gemm.mm(a, b), a @ b, rtol=1e-5, atol=1e-4)
        import gdnplan as gp
        from gdnplan.assets import default_weights
        scene = gp.make_scene("b", seed=0)
        q = scene.robot.sample(30, seed=0)
        fast, reference = (gp.load_model(default_weights(scene)) for _ in range(2))
        fast.fused, reference.fused = True, False
        (d1, g1), (d2, g2) = fast.distance_and_grad(scene, q), reference.distance_and_grad(scene, q)
        assert np.allclose(d1, d2, atol=1e-5) and np.allclose(g1, g2, atol=1e-4)
        print("ok")
        """
    )
    run = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr[-2000:]
    assert run.stdout.strip().endswith("ok")
