"""The kernels' products: numba's numpy.dot (scipy's BLAS) vs gemm.mm (torch's BLAS), side by
side in one run, on the shapes of the fused passes (a tile of R rows times a W × W weight:
W = 16 in the shipped (d), (e) networks, 32 in the others), with the 2048² float32 matmul of
this thread as the peak. The W = 16 rows bound what a 16-wide network's products can reach; a
whole pass adds gathers and element-wise work whose cost grows with W while its FLOPs grow
with W².

Both on one thread (scipy's BLAS limited by threadpoolctl, as the kernels run it; gemm.mm
sets MKL's thread-local count). GFLOP/s = 2 R K N per product over its thread CPU seconds
(best of the repeats, each 200 products in one compiled loop).

    python benchmarks/gemm.py [--repeats 5] [--rows 256 2016 4096] [--widths 16 32]
"""

from __future__ import annotations

import itertools

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
    p.add_argument("--widths", type=int, nargs="+", default=[16, 32])
    args = common.parse(p)
    report = common.Report(args, "Products of the fused kernels", common.first_paragraph(__doc__))
    peak = matmul_gflops()
    report.text(f"gemm.BACKEND: {gemm.BACKEND}; float32 matmul peak {peak:.1f} GFLOP/s.")
    table = report.table(
        "width W",
        "rows R",
        "dtype",
        "numpy.dot GFLOP/s (share)",
        "gemm.mm GFLOP/s (share)",
        "mm / dot time",
    )
    rng = np.random.default_rng(0)
    for width, rows, dtype in itertools.product(args.widths, args.rows, (np.float32, np.float64)):
        a = rng.normal(size=(rows, width)).astype(dtype)
        w = rng.normal(size=(width, width)).astype(dtype)
        flops = 2 * rows * width * width * CALLS / 1e9
        with fused._serial_blas():  # as the kernels call them: one thread each
            dot = cpu_seconds(lambda a=a, w=w: _numpy_dot(a, w, CALLS), args.repeats)
            mm = cpu_seconds(lambda a=a, w=w: _gemm_mm(a, w, CALLS), args.repeats)
        table.add(
            width,
            rows,
            np.dtype(dtype).name,
            f"{flops / dot:.1f} ({100 * flops / dot / peak:.0f} %)",
            f"{flops / mm:.1f} ({100 * flops / mm / peak:.0f} %)",
            f"{mm / dot:.2f}×",
        )
    report.write()


if __name__ == "__main__":
    main()
