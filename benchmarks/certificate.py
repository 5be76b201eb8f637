"""Cost of the continuous certificate on planned paths, by reporting tolerance.

For each shipped problem, plans with coal once, then certifies the plan at margin 0 with
tol = inf (the proof only, as RRT edge checks use it), 1 mm (plan's default) and 0.1 mm: the
proven lower bound, the smallest checked distance, coal evaluations and time (median of the
repeats after one warm-up call).

    python benchmarks/certificate.py --threads 1 [--repeats 3]
"""

from __future__ import annotations

import math

import common

import gdnplan as gp
from gdnplan.ccd import certify_path

PROBLEMS = ("fetch_reach", "planar7_d", "planar2_square")
TOLS = (math.inf, 1e-3, 1e-4)


def main() -> None:
    p = common.parser("certificate", __doc__)
    p.add_argument("--repeats", type=int, default=3)
    args = common.parse(p)
    report = common.Report(args, "The certificate as a proof", common.first_paragraph(__doc__))
    table = report.table(
        "problem", "tol (m)", "proven", "lower bound (m)", "sampled min (m)", "checks", "time (s)"
    )
    for name in PROBLEMS:
        problem = gp.Problem.from_toml(common.ROOT / "problems" / f"{name}.toml")
        q = gp.plan(problem, collision="coal").q
        calls = {t: (lambda t=t, s=problem.scene, q=q: certify_path(s, q, tol=t)) for t in TOLS}
        times = common.time_calls(calls, repeats=args.repeats)
        for tol, call in calls.items():
            cert = call()
            table.add(
                name,
                f"{tol:g}",
                cert.ok,
                f"{cert.lower_bound:.5f}",
                f"{cert.min_distance:.5f}",
                cert.n_checks,
                f"{times[tol].median:.3f}",
            )
    report.write()


if __name__ == "__main__":
    main()
