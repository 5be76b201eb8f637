"""Time per configuration of the exact 3-D signed distance (and + gradient) of gdnplan.arm3d.

Usage: python benchmarks/coal3d_distance.py [--threads 1] [--n 200] [--repeats 3] [--out PATH]

The UR5e (collision cylinders and boxes) and the Panda (collision meshes as convex hulls)
among 20 random boxes (``random_boxes(robot, 20, seed)``, one scene per robot), self-collision
included; the overall minimum with and without the broad phase, and the pairs sent to coal's
narrow phase (GJK/EPA) per configuration. Writes a markdown table (best of the repeats) to
benchmarks/results/coal3d_distance.md and prints it.
"""

from __future__ import annotations

import argparse
import os
import sys


def parse() -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--threads", type=int, default=1, help="BLAS/OpenMP threads")
    parser.add_argument("--n", type=int, default=200, help="configurations per robot")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--out", default="benchmarks/results/coal3d_distance.md")
    return parser.parse_args()


ARGS = parse() if __name__ == "__main__" else None
if ARGS is not None:  # before numpy is imported
    for var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
        os.environ[var] = str(ARGS.threads)

import datetime  # noqa: E402
import platform  # noqa: E402
import time  # noqa: E402

import coal  # noqa: E402
import numpy as np  # noqa: E402
import pinocchio as pin  # noqa: E402

from gdnplan.arm3d import Checker3D, load_robot3d, random_boxes  # noqa: E402


def header(command: str) -> str:
    """Command, machine, date and library versions of a results file (a local stand-in for
    the shared benchmarks header)."""
    machine = platform.processor() or platform.machine()
    return "\n".join(
        [
            f"- command: `{command}`",
            f"- machine: {machine}, {os.cpu_count()} cores ({platform.system()} "
            f"{platform.release()}), Python {platform.python_version()}",
            f"- date: {datetime.datetime.now(datetime.UTC).strftime('%Y-%m-%d %H:%M UTC')}",
            f"- coal {coal.__version__}, pinocchio {pin.__version__}, numpy {np.__version__}",
        ]
    )


def best(fn, repeats: int) -> tuple[float, object]:
    times, out = [], None
    for _ in range(repeats):
        start = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - start)
    return min(times), out


def rows(args: argparse.Namespace) -> list[str]:
    out = []
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
            out.append(
                f"| {name} | {len(robot.shapes)} | {checker.n_pairs} "
                f"({len(robot.self_pairs)} self) | {'on' if broad else 'off'} "
                f"| {np.mean(res.narrow):.1f} | {1e3 * t_d / args.n:.3f} "
                f"| {1e3 * t_g / args.n:.3f} | {colliding:.0%} |"
            )
    return out


def main(args: argparse.Namespace) -> None:
    command = "python " + " ".join(sys.argv)
    table = [
        "# coal 3-D signed distance per configuration",
        "",
        header(command),
        f"- {args.n} random configurations per robot within its joint limits, 20 random boxes "
        f"(seed {args.seed}), best of {args.repeats} repeats; times are per configuration",
        "",
        "| robot | shapes | pairs | broad phase | narrow-phase pairs / config "
        "| distance (ms) | distance + gradient (ms) | configs in collision |",
        "|---|---|---|---|---|---|---|---|",
        *rows(args),
        "",
    ]
    text = "\n".join(table)
    os.makedirs(os.path.dirname(args.out) or ".", exist_ok=True)
    with open(args.out, "w", encoding="utf-8") as f:
        f.write(text)
    print(text)


if __name__ == "__main__":
    main(ARGS)
