"""GraphDistNet vs coal constraints in the same Ipopt transcription, side by side.

Random planar2 reaching problems on environment (b) (random scene seed each; start and goal
clearance ≥ margin + 0.03 m, not provably infeasible, straight line in collision so the
optimiser has work to do), T = 20, margin --margin (0.02 m); every plan judged by the
certified coal check.

    .venv/bin/python benchmarks/trajopt_models.py [--n 10] [--seed 0] [--env b] [--margin 0.02]

Prints a markdown table and writes it to results/trajopt_models.md.
"""

from __future__ import annotations

import argparse
import datetime
import os
import sys

import numpy as np
from trajopt_ingredients import ROOT, machine

import gdnplan as gp
from gdnplan.trajopt import Problem, TrajoptOptions, plan, straight_line


def make_problems(
    n: int, seed: int, env: str, margin: float = 0.02, clearance: float = 0.03
) -> list[Problem]:
    """n problems whose straight joint-space line is not certified free."""
    rng = np.random.default_rng(seed)
    out = []
    while len(out) < n:
        scene = gp.make_scene(env, seed=int(rng.integers(2**31)))
        q = scene.robot.sample(2, seed=int(rng.integers(2**31)))
        if np.any(gp.signed_distance(scene, q) <= margin + clearance):
            continue
        try:
            p = Problem(scene=scene, start=q[0], goal=q[1], waypoints=20, margin=margin)
        except gp.InfeasibleProblemError:
            continue
        if not gp.verify_path(scene, straight_line(q[0], q[1], 20), margin=margin)[0]:
            out.append(p)
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=10)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--env", default="b")
    ap.add_argument("--margin", type=float, default=0.02, help="m; learned models need their error")
    args = ap.parse_args()
    host = machine()
    weights = ROOT / "weights" / f"{args.env}.safetensors"
    models = {"coal": gp.CoalModel(), "GraphDistNet": gp.load_model(weights)}
    problems = make_problems(args.n, args.seed, args.env, args.margin)
    lines = [
        "| constraints | verified successes | median time (s) | mean time (s) "
        "| median iterations | median model calls |",
        "|---|---|---|---|---|---|",
    ]
    for name, model in models.items():
        plans = []
        for i, p in enumerate(problems):
            r = plan(p, collision=model, seed=i, options=TrajoptOptions())
            print(f"{name} {i}: {r.success} {r.solve_time:.2f} s {r.reason}", file=sys.stderr)
            plans.append(r)
        t = [r.solve_time for r in plans]
        lines.append(
            f"| {name} | {sum(r.success for r in plans)}/{len(plans)} | {np.median(t):.2f} "
            f"| {np.mean(t):.2f} | {np.median([r.iterations for r in plans]):.0f} "
            f"| {np.median([r.model_calls for r in plans]):.0f} |"
        )
    text = (
        f"# GraphDistNet vs coal constraints (Ipopt, environment ({args.env}))\n\n"
        f"{args.n} problems whose straight line collides, T = 20, margin {args.margin} m, "
        "start/goal clearance ≥ margin + 0.03 m, default "
        "TrajoptOptions (per-link rows for coal only: GraphDistNet has one distance), success = "
        f"certified coal check. Weights: `weights/{args.env}.safetensors`.\n\n"
        + "\n".join(lines)
        + f"\n\n- machine: {host}; load average at the end {os.getloadavg()[0]:.1f}\n"
        f"- command: `.venv/bin/python benchmarks/trajopt_models.py --n {args.n} "
        f"--seed {args.seed} --env {args.env} --margin {args.margin}`\n"
        f"- date: {datetime.datetime.now(datetime.UTC):%Y-%m-%d %H:%M} UTC\n"
    )
    print(text)
    out = ROOT / "results" / "trajopt_models.md"
    tmp = out.with_suffix(".tmp")
    tmp.write_text(text)
    tmp.replace(out)


if __name__ == "__main__":
    main()
