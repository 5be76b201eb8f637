"""Cost of the continuous certificate on planned paths, by reporting tolerance.

For each shipped problem, plans with coal once, then certifies the plan at margin 0 with
tol = inf (the proof only, as RRT edge checks use it), 1 mm (plan's default) and 0.1 mm: coal
evaluations, time, the proven lower bound and the smallest checked distance.

    python benchmarks/certificate.py
"""

from __future__ import annotations

import math
import time

import gdnplan as gp
from gdnplan.ccd import certify_path

PROBLEMS = ("fetch_reach", "planar7_d", "planar2_square")


def main() -> None:
    print("| problem | tol (m) | proven | lower bound (m) | sampled min (m) | checks | time (s) |")
    print("|---|---|---|---|---|---|---|")
    for name in PROBLEMS:
        problem = gp.Problem.from_toml(f"problems/{name}.toml")
        q = gp.plan(problem, collision="coal").q
        for tol in (math.inf, 1e-3, 1e-4):
            t0 = time.perf_counter()
            cert = certify_path(problem.scene, q, tol=tol)
            dt = time.perf_counter() - t0
            print(
                f"| {name} | {tol:g} | {cert.ok} | {cert.lower_bound:.5f} | "
                f"{cert.min_distance:.5f} | {cert.n_checks} | {dt:.3f} |"
            )


if __name__ == "__main__":
    main()
