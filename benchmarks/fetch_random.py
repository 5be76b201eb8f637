"""Random fetch benchmark (paper Table II, third row): GraphDistNet vs coal constraints.

Each problem is a random fetch layout (storage size, placement, riser, entrance height, stick
size; ``make_scene("fetch", seed=s)`` for s = --first … --first + --n − 1, never 0 and never a
layout of the ur5e training data, whose fetch seeds start at 10 000): reach in with the gripper
open from q_home to q_grasp (fingers around the stick through the entrance), T = 30 waypoints,
margin 0.01 m, the same Ipopt transcription and default TrajoptOptions for both models.
Success = certified dense coal check and goal reached.

    .venv/bin/python benchmarks/fetch_random.py [--n 20] [--first 1] [--margin 0.01]

Prints a markdown table and writes it to results/table2_fetch.md.
"""

from __future__ import annotations

import argparse
import datetime
import hashlib
import os
import sys

import numpy as np
from trajopt_ingredients import ROOT, machine

import gdnplan as gp
from gdnplan.trajopt import Plan, Problem, plan


def make_problems(n: int, first: int, margin: float) -> list[Problem]:
    """Reach-in problems q_home → q_grasp on fetch seeds first … first + n − 1 (open gripper)."""
    out = []
    for s in range(first, first + n):
        scene = gp.make_scene("fetch", seed=s, gripper="open")
        out.append(
            Problem(
                scene=scene,
                start=scene.info["q_home"],
                goal=scene.info["q_grasp"],
                waypoints=30,
                margin=margin,
            )
        )
    return out


CONVERGED = ("Solve_Succeeded", "Solved_To_Acceptable_Level")


def converged(r: Plan) -> bool:
    """The accepted path is a converged solve (or the straight line, certified free)."""
    return r.status in CONVERGED or r.status.startswith("straight line")


def row(name: str, plans: list[Plan]) -> str:
    t = [r.solve_time for r in plans]
    ok = [r for r in plans if r.success]
    clear = f"{np.median([r.min_distance for r in ok]):.4f}" if ok else "–"
    return (
        f"| {name} | {len(ok)}/{len(plans)} | {sum(converged(r) for r in ok)}/{len(plans)} "
        f"| {np.median(t):.2f} | {np.mean(t):.2f} "
        f"| {clear} | {np.median([r.iterations for r in plans]):.0f} |"
    )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=20)
    ap.add_argument("--first", type=int, default=1, help="first fetch seed (≥ 1)")
    ap.add_argument("--margin", type=float, default=0.01, help="constraint d ≥ margin (m)")
    ap.add_argument("--out", default=str(ROOT / "results" / "table2_fetch.md"))
    args = ap.parse_args()
    if args.first < 1:
        sys.exit("--first: seed 0 is the canonical layout; random layouts start at 1")
    host = machine()  # git sha of the code that runs, taken before the (long) run
    weights = ROOT / "weights" / "ur5e.safetensors"
    sha = hashlib.sha256(weights.read_bytes()).hexdigest()[:12]
    models = {"GraphDistNet + Ipopt": gp.load_model(weights), "coal + Ipopt": gp.CoalModel()}
    problems = make_problems(args.n, args.first, args.margin)
    lines = [
        "| constraints | certified successes | of which converged | median time (s) "
        "| mean time (s) | median clearance of successes (m) | median iterations |",
        "|---|---|---|---|---|---|---|",
    ]
    per_problem: dict[str, list[Plan]] = {}
    for name, model in models.items():
        plans = []
        for p in problems:
            r = plan(p, collision=model)
            print(
                f"{name} seed {p.scene.seed}: {r.success} {r.min_distance:+.4f} m "
                f"{r.solve_time:.2f} s {r.reason}",
                file=sys.stderr,
                flush=True,
            )
            plans.append(r)
        per_problem[name] = plans
        lines.append(row(name, plans))
    lines.append(
        "| paper: GraphDistNet + Adam (Table II, random fetch) | 14/20 | – | – | – | – | – |"
    )
    detail = ["| fetch seed | " + " | ".join(models) + " |", "|---" * (len(models) + 1) + "|"]
    for i, p in enumerate(problems):
        cells = [
            f"{'ok' if r.success else 'FAIL'} {r.min_distance:+.4f} m, {r.solve_time:.1f} s, "
            f"{r.status}"
            for r in (per_problem[name][i] for name in models)
        ]
        detail.append(f"| {p.scene.seed} | " + " | ".join(cells) + " |")
    load = os.getloadavg()[0]
    text = (
        "# Table II, random fetch: GraphDistNet vs coal constraints (UR5e, Ipopt)\n\n"
        f"{args.n} random fetch layouts (fetch seeds {args.first}–{args.first + args.n - 1}, "
        "unseen in training), reach in with the open gripper q_home → q_grasp, T = 30, "
        f"margin {args.margin} m, default TrajoptOptions; success = certified dense coal check "
        "and goal reached; *converged*: the accepted path is Ipopt's converged solution (or "
        "the certified straight line), not the last iterate of a solve that stopped otherwise "
        "(e.g. Infeasible_Problem_Detected when the learned d̂ at the goal is below the margin) "
        "that the coal check certified anyway. Seed paths (RRT-Connect) are checked with coal "
        f"for both models. Weights: `weights/ur5e.safetensors` (sha256 {sha}…).\n\n"
        + "\n".join(lines)
        + "\n\nPer problem (certified coal clearance, wall time, solver status):\n\n"
        + "\n".join(detail)
        + f"\n\n- machine: {host}; load average at the end {load:.1f} (shared machine)\n"
        f"- command: `.venv/bin/python benchmarks/fetch_random.py --n {args.n} "
        f"--first {args.first} --margin {args.margin}`\n"
        f"- date: {datetime.datetime.now(datetime.UTC).strftime('%Y-%m-%d %H:%M')} UTC\n"
    )
    print(text)
    tmp = f"{args.out}.tmp"
    with open(tmp, "w") as f:
        f.write(text)
    os.replace(tmp, args.out)


if __name__ == "__main__":
    main()
