"""Planning in 3-D: gdnplan (coal + Ipopt) beside OMPL RRT-Connect on random reaching problems.

Usage: python benchmarks/plan3d.py --threads 1 [--robots ur5e panda] [--problems 20]
       [--rrt-time 5] [--ompl-time 10] [--out benchmarks/results/plan3d.md]

Problems: :func:`gdnplan.arm3d.problem3d.reaching_problems` (seed 0): for each robot, problem
i is the robot among 20 random boxes (scene seed i, box sides and base clearance from
``BOXES``), a start and a goal clear of the margin (0.02 m) within the joint box (the limits
cut to ±π), and a straight joint-space line that collides. The share of uniformly random
configurations in collision is measured on the same scenes (the 3-D counterpart of environment
(d)'s 25–40 %).

Methods, on every problem in one run:

- gdnplan: ``gp.plan(problem, collision="coal")`` with its defaults (Ipopt, RRT-Connect seeds,
  the 3-D conservative-advancement certificate at the margin, self-collision included) except
  ``SeedConfig.rrt_time = --rrt-time`` (s, wall time of one RRT-Connect run; the default 5);
- OMPL RRT-Connect + its path simplifier (:func:`gdnplan.ompl_planner.plan_ompl`), planning
  time limit ``--ompl-time`` s, on the same validity rule (proven state distance > margin,
  motions accepted by the same edge certificate).

Every returned path is certified once more here (:func:`gdnplan.exact.certify` at the margin)
and counts as failed unless it certifies. Metrics: success, median wall time, path cost
Σ‖Δq‖² after resampling to the problem's T waypoints equally spaced in joint-space arc length
(:func:`gdnplan.path_metrics.resampled_cost`) and the certified clearance (m).
"""

from __future__ import annotations

import statistics
import time

import common
import numpy as np

import gdnplan as gp
from gdnplan.arm3d.problem3d import BOXES, collision_fraction, reaching_problems
from gdnplan.exact import certify
from gdnplan.ompl_planner import plan_ompl
from gdnplan.path_metrics import resampled_cost


def run_gdnplan(problem, rrt_time: float) -> dict:
    t0 = time.perf_counter()
    config = gp.PlanConfig(seed=gp.SeedConfig(rrt_time=rrt_time))
    result = gp.plan(problem, collision="coal", solver=config)
    elapsed = time.perf_counter() - t0
    cert = certify(problem.scene, result.q, problem.certified_clearance)
    ok = bool(result.success and cert.ok)
    return {
        "ok": ok,
        "time": elapsed,
        "cost": resampled_cost(result.q, problem.waypoints) if ok else None,
        "clearance": cert.lower_bound if ok else None,
        "note": "" if ok else result.reason[:80],
    }


def run_ompl(problem, time_limit: float, seed: int) -> dict:
    res = plan_ompl(
        problem.scene,
        problem.start,
        problem.goal,
        problem.certified_clearance,
        time_limit=time_limit,
        seed=seed,
        lower=problem.lower,
        upper=problem.upper,
    )
    ok = bool(res.success)
    if ok:  # certified again here, as gdnplan's path
        ok = certify(problem.scene, res.path, problem.certified_clearance).ok
    return {
        "ok": ok,
        "time": res.time,
        "cost": resampled_cost(res.path, problem.waypoints) if ok else None,
        "clearance": res.clearance if ok else None,
        "note": "" if ok else res.status,
    }


def fmt(x, spec: str = ".3f") -> str:
    return "—" if x is None else format(x, spec)


def summary(rows: list[dict]) -> tuple[str, str, str, str]:
    ok = [r for r in rows if r["ok"]]
    times = statistics.median(r["time"] for r in rows) if rows else None
    cost = statistics.median(r["cost"] for r in ok) if ok else None
    clear = min(r["clearance"] for r in ok) if ok else None
    return f"{len(ok)}/{len(rows)}", fmt(times, ".2f"), fmt(cost), fmt(clear, "+.4f")


def main(argv=None) -> None:
    p = common.parser("plan3d", __doc__)
    p.add_argument("--robots", nargs="+", default=["ur5e", "panda"])
    p.add_argument("--problems", type=int, default=20)
    p.add_argument("--rrt-time", type=float, default=5.0, help="gdnplan's RRT-Connect limit (s)")
    p.add_argument("--ompl-time", type=float, default=10.0, help="OMPL planning time limit (s)")
    args = common.parse(p, argv)
    report = common.Report(
        args, "Planning in 3-D: gdnplan (coal + Ipopt) and OMPL RRT-Connect", __doc__
    )
    totals = report.table(
        "robot", "problems", "colliding configs", "method", "certified", "median time (s)",
        "median path cost (rad²)", "smallest certified clearance (m)",
    )  # fmt: skip
    for name in args.robots:
        problems = reaching_problems(name, args.problems, seed=0)
        shares = [collision_fraction(p.scene, 200, seed=i) for i, p in enumerate(problems)]
        share = (
            f"{100 * np.mean(shares):.0f} % ({100 * min(shares):.0f}–{100 * max(shares):.0f} %, "
            f"boxes {BOXES[name][0][0]}–{BOXES[name][0][1]} m, ≥ {BOXES[name][1]} m from the base)"
        )
        detail = report.table(
            "robot", "problem", "gdnplan ok", "time (s)", "cost", "clearance (m)",
            "OMPL ok", "time (s)", "cost", "clearance (m)", "note",
        )  # fmt: skip
        rows = {"gdnplan": [], "OMPL RRT-Connect": []}
        for i, problem in enumerate(problems):
            g = run_gdnplan(problem, args.rrt_time)
            o = run_ompl(problem, args.ompl_time, seed=i)
            rows["gdnplan"].append(g)
            rows["OMPL RRT-Connect"].append(o)
            detail.add(
                name, i, g["ok"], fmt(g["time"], ".2f"), fmt(g["cost"]),
                fmt(g["clearance"], "+.4f"), o["ok"], fmt(o["time"], ".2f"), fmt(o["cost"]),
                fmt(o["clearance"], "+.4f"), "; ".join(x["note"] for x in (g, o) if x["note"]),
            )  # fmt: skip
            report.write()  # an interrupted run keeps its rows
        for method, results in rows.items():
            totals.add(name, len(problems), share, method, *summary(results))
        report.write()


if __name__ == "__main__":
    main()
