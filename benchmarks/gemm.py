"""The kernels' products: numba's numpy.dot (scipy's BLAS) vs gemm.mm (torch's BLAS), side by
side in one run, on the shapes of the fused passes (a tile of R rows times a 32 × 32
weight), with the 2048² float32 matmul of this thread as the peak.

Both on one thread (scipy's BLAS limited by threadpoolctl, as the kernels run it; gemm.mm
sets MKL's thread-local count). GFLOP/s = 2 R K N per product over its thread CPU seconds
(best of the repeats, each 200 products in one compiled loop).

    python benchmarks/gemm.py [--repeats 5] [--rows 256 2016 4096]
"""

from __future__ import annotations

import common
import numba
import numpy as np
from inference import cpu_seconds, matmul_gflops

from gdnplan.models.graphdistnet import fused, gemm

CALLS = 200


@numba.njit(cache=True)
def _numpy_dot(a, w, calls):
    for _ in range(calls):
        np.dot(a, w)


@numba.njit(cache=True)
def _gemm_mm(a, w, calls):
    for _ in range(calls):
        gemm.mm(a, w)


def main() -> None:
    p = common.parser("gemm", __doc__)
    p.add_argument("--repeats", type=int, default=5)
    p.add_argument("--rows", type=int, nargs="+", default=[256, 2016, 4096])
    args = common.parse(p)
    report = common.Report(args, "Products of the fused kernels", common.first_paragraph(__doc__))
    peak = matmul_gflops()
    report.text(f"gemm.BACKEND: {gemm.BACKEND}; float32 matmul peak {peak:.1f} GFLOP/s.")
    table = report.table(
        "rows R", "dtype", "numpy.dot GFLOP/s (share)", "gemm.mm GFLOP/s (share)", "mm / dot time"
    )
    rng = np.random.default_rng(0)
    for rows in args.rows:
        for dtype in (np.float32, np.float64):
            a = rng.normal(size=(rows, 32)).astype(dtype)
            w = rng.normal(size=(32, 32)).astype(dtype)
            flops = 2 * rows * 32 * 32 * CALLS / 1e9
            with fused._serial_blas():  # as the kernels call them: one thread each
                dot = cpu_seconds(lambda a=a, w=w: _numpy_dot(a, w, CALLS), args.repeats)
                mm = cpu_seconds(lambda a=a, w=w: _gemm_mm(a, w, CALLS), args.repeats)
            table.add(
                rows,
                np.dtype(dtype).name,
                f"{flops / dot:.1f} ({100 * flops / dot / peak:.0f} %)",
                f"{flops / mm:.1f} ({100 * flops / mm / peak:.0f} %)",
                f"{mm / dot:.2f}×",
            )
    report.write()


if __name__ == "__main__":
    main()
