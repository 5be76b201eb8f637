"""Time per configuration of the exact 3-D signed distance (and + gradient) of gdnplan.arm3d.

The UR5e (collision cylinders and boxes) and the Panda (collision meshes as convex hulls)
among 20 random boxes (``random_boxes(robot, 20, seed)``, one scene per robot), self-collision
included; the overall minimum with and without the broad phase, and the pairs sent to coal's
narrow phase (GJK/EPA) per configuration; best of the repeats.

    python benchmarks/coal3d_distance.py --threads 1 [--n 200] [--repeats 3] [--seed 0]

``--threads`` also sets the BLAS/OpenMP threads (before numpy is imported).
"""

from __future__ import annotations

import argparse
import os

import common


def make_parser() -> argparse.ArgumentParser:
    p = common.parser("coal3d_distance", __doc__)
    p.add_argument("--n", type=int, default=200, help="configurations per robot")
    p.add_argument("--repeats", type=int, default=3)
    p.add_argument("--seed", type=int, default=0)
    return p


if __name__ == "__main__":  # BLAS/OpenMP threads before numpy is imported
    _threads = make_parser().parse_known_args()[0].threads
    for var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
        os.environ[var] = str(max(_threads, 1))

import time  # noqa: E402

import coal  # noqa: E402
import numpy as np  # noqa: E402
import pinocchio as pin  # noqa: E402

from gdnplan.arm3d import Checker3D, load_robot3d, random_boxes  # noqa: E402


def best(fn, repeats: int) -> tuple[float, object]:
    times, out = [], None
    for _ in range(repeats):
        start = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - start)
    return min(times), out


def measure(args: argparse.Namespace, table: common.Table) -> None:
    """One row per robot and broad-phase setting (times per configuration)."""
    for name in ("ur5e", "panda"):
        robot = load_robot3d(name)
        scene = random_boxes(robot, 20, seed=args.seed)
        checker = Checker3D(scene)
        q = robot.random_configurations(args.n, np.random.default_rng(args.seed))
        colliding = float(np.mean(checker.evaluate(q).distance < 0))
        for broad in (True, False):
            t_d, res = best(
                lambda b=broad, c=checker, q=q: c.evaluate(q, broad_phase=b), args.repeats
            )
            t_g, _ = best(
                lambda b=broad, c=checker, q=q: c.evaluate(q, broad_phase=b, gradient=True),
                args.repeats,
            )
            table.add(
                name,
                len(robot.shapes),
                f"{checker.n_pairs} ({len(robot.self_pairs)} self)",
                "on" if broad else "off",
                f"{np.mean(res.narrow):.1f}",
                f"{1e3 * t_d / args.n:.3f}",
                f"{1e3 * t_g / args.n:.3f}",
                f"{colliding:.0%}",
            )


def main() -> None:
    args = common.parse(make_parser())
    report = common.Report(
        args, "coal 3-D signed distance per configuration", common.first_paragraph(__doc__)
    )
    report.text(
        f"coal {coal.__version__}, pinocchio {pin.__version__}; {args.n} random configurations "
        f"per robot within its joint limits, 20 random boxes (seed {args.seed}), best of "
        f"{args.repeats} repeats; times are per configuration."
    )
    table = report.table(
        "robot",
        "shapes",
        "pairs",
        "broad phase",
        "narrow-phase pairs / config",
        "distance (ms)",
        "distance + gradient (ms)",
        "configs in collision",
    )
    measure(args, table)
    report.write()


if __name__ == "__main__":
    main()
