"""Planning in 3-D: gdnplan (coal + Ipopt) beside OMPL RRT-Connect on random reaching problems,
or (``--learned``) gdnplan with GraphDistNet-3D constraints beside gdnplan with coal.

Usage: python benchmarks/plan3d.py --threads 1 [--robots ur5e panda] [--problems 20]
       [--rrt-time 5] [--ompl-time 10] [--out benchmarks/results/plan3d.md]
       python benchmarks/plan3d.py --threads 1 --robots ur5e --learned ur5e_boxes3d_preliminary
       [--first K] --out benchmarks/results/plan3d_graphdistnet3d.md

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

With ``--learned WEIGHTS`` (shipped weights by name or a ``.safetensors`` path of a
GraphDistNet-3D card) the methods are instead ``gp.plan(problem, collision=model)`` with the
learned robot–obstacle distance (self-collision exact; Ipopt through the same casadi callback,
refine rounds with coal rows where the certificate fails) and ``gp.plan(problem,
collision="coal")``, both with the same settings, run problem by problem in alternating order
(coal first on even problems, the learned model first on odd ones) so that a drift of the
machine's load hits both alike. Per method: certified or not, wall time, the calling thread's
CPU time (``time.thread_time``) and the process's (``time.process_time``, every thread),
path cost, certified clearance, batched model calls; and the median paired ratios learned /
coal of wall and CPU time over the problems both certified. The learned model is warmed up
once (compiled pass loaded, one scene's obstacle features) before the first problem.

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


def run_paired(problem, collision, rrt_time: float) -> dict:
    """gdnplan with ``collision`` (a name or a model): certified, wall / thread / process time."""
    config = gp.PlanConfig(seed=gp.SeedConfig(rrt_time=rrt_time))
    w0, t0, p0 = time.perf_counter(), time.thread_time(), time.process_time()
    result = gp.plan(problem, collision=collision, solver=config)
    wall = time.perf_counter() - w0
    thread, process = time.thread_time() - t0, time.process_time() - p0
    cert = certify(problem.scene, result.q, problem.certified_clearance)
    ok = bool(result.success and cert.ok)
    return {
        "ok": ok,
        "time": wall,
        "thread": thread,
        "process": process,
        "calls": result.model_calls,
        "cost": resampled_cost(result.q, problem.waypoints) if ok else None,
        "clearance": cert.lower_bound if ok else None,
        "note": "" if ok else result.reason[:120],
    }


def compare_learned(args, report: common.Report) -> None:
    """The ``--learned`` mode: GraphDistNet-3D and coal constraints on the same problems."""
    from gdnplan.models import load_model

    model = load_model(args.learned, threads=args.threads)
    samples = model.card.get("training", {}).get("samples")
    report.text(
        f"Learned model: `{args.learned}` (card: env {model.card.get('env')!r}, "
        f"training.samples {samples}, hidden-seed AUC {model.card.get('test', {}).get('auc')}, "
        f"compiled pass {model.fused}); RRT-Connect limit {args.rrt_time} s."
    )
    totals = report.table(
        "robot", "method", "certified", "median wall (s)", "median thread CPU (s)",
        "median process CPU (s)", "median model calls", "median path cost (rad²)",
        "smallest certified clearance (m)",
    )  # fmt: skip
    ratios = report.table(
        "robot", "problems both certified", "median wall ratio learned/coal",
        "median thread CPU ratio", "median process CPU ratio",
    )  # fmt: skip
    for name in args.robots:
        problems = reaching_problems(name, args.first + args.problems, seed=0)[args.first :]
        model.distance_and_grad(problems[0].scene, problems[0].start[None])  # warm-up
        detail = report.table(
            "robot", "problem", "first", "method", "certified", "wall (s)", "thread CPU (s)",
            "process CPU (s)", "model calls", "cost", "clearance (m)", "note",
        )  # fmt: skip
        rows: dict[str, list[dict]] = {"GraphDistNet-3D": [], "coal": []}
        for i, problem in enumerate(problems, start=args.first):
            order = ["coal", "GraphDistNet-3D"][:: 1 if i % 2 == 0 else -1]
            for method in order:
                r = run_paired(problem, model if method != "coal" else "coal", args.rrt_time)
                rows[method].append(r)
                detail.add(
                    name, i, order[0], method, r["ok"], fmt(r["time"], ".2f"),
                    fmt(r["thread"], ".2f"), fmt(r["process"], ".2f"), r["calls"],
                    fmt(r["cost"]), fmt(r["clearance"], "+.4f"), r["note"],
                )  # fmt: skip
                report.write()  # an interrupted run keeps its rows
        for method, results in rows.items():
            ok = [r for r in results if r["ok"]]
            totals.add(
                name, method, f"{len(ok)}/{len(results)}",
                *(fmt(statistics.median(r[k] for r in results), ".2f")
                  for k in ("time", "thread", "process")),
                fmt(statistics.median(r["calls"] for r in results), ".0f"),
                fmt(statistics.median(r["cost"] for r in ok) if ok else None),
                fmt(min(r["clearance"] for r in ok) if ok else None, "+.4f"),
            )  # fmt: skip
        pairs = [
            (g, c) for g, c in zip(rows["GraphDistNet-3D"], rows["coal"], strict=True)
            if g["ok"] and c["ok"]
        ]  # fmt: skip
        ratios.add(
            name, len(pairs),
            *(fmt(statistics.median(g[k] / c[k] for g, c in pairs) if pairs else None, ".2f")
              for k in ("time", "thread", "process")),
        )  # fmt: skip
        report.write()


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
    p.add_argument(
        "--first", type=int, default=0, help="--learned: skip the first K problems (split runs)"
    )
    p.add_argument(
        "--learned",
        metavar="WEIGHTS",
        help="GraphDistNet-3D weights: compare learned and coal constraints instead of OMPL",
    )
    args = common.parse(p, argv)
    if args.learned is not None:
        title = "Planning in 3-D: GraphDistNet-3D and coal constraints, Ipopt"
        compare_learned(args, common.Report(args, title, __doc__))
        return
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
