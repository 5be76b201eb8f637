"""What each trajectory-optimisation ingredient adds, measured side by side on the same problems.

20 random planar7 reaching problems on environment (d) (each with its own random scene seed;
start and goal collision-free with 0.05 m clearance, end effectors ≥ 1 m apart, not provably
infeasible: Problem rejects pairs whose first-link sweep collides), coal
constraints, Ipopt, T = 20 waypoints, margin 0.02 m. Every variant's plan is judged by the
certified coal check (conservative advancement, ≤ 1 mm motion between checks).

    python benchmarks/trajopt_ingredients.py --threads 1 [--n 20] [--seed 0]
"""

from __future__ import annotations

import sys
from dataclasses import dataclass

import common
import numpy as np

import gdnplan as gp
from gdnplan.trajopt import (
    IpoptConfig,
    Plan,
    PlanConfig,
    Problem,
    RefineConfig,
    SeedConfig,
    plan,
    tip_position,
)

STRAIGHT, NO_CCD = SeedConfig(initial="straight"), RefineConfig(ccd=False)
ONE_ROW = IpoptConfig(per_link=False)  # one overall distance row per check point
VARIANTS = {
    "straight-line guess (prototype baseline)": PlanConfig(STRAIGHT, NO_CCD, ONE_ROW),
    "RRT-Connect seed (line kept when certified free)": PlanConfig(
        refine=NO_CCD, optimizer=ONE_ROW
    ),
    "+ CCD certificate (re-solve with subdivided uncertified segments)": PlanConfig(
        optimizer=ONE_ROW
    ),
    "+ per-link rows (default)": PlanConfig(),
    "per-link without CCD certificate": PlanConfig(refine=NO_CCD),
}
SOLVED = ("Solve_Succeeded", "Solved_To_Acceptable_Level")


def make_problems(n: int, seed: int, min_tip: float = 1.0, clearance: float = 0.05) -> list:
    """n problems on env d: random scene seed, random free start/goal with tips ≥ min_tip apart."""
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(n):
        scene = gp.make_scene("d", seed=int(rng.integers(2**31)))
        robot = scene.robot
        while True:
            q = rng.uniform(robot.lower, robot.upper, (2, robot.dof))
            far = np.linalg.norm(np.diff(tip_position(robot, q), axis=0)) >= min_tip
            if not far or np.any(gp.signed_distance(scene, q) <= clearance):
                continue
            try:
                problem = Problem(scene=scene, start=q[0], goal=q[1], waypoints=20, margin=0.02)
            except gp.InfeasibleProblemError:  # provably infeasible (first-link barrier)
                continue
            out.append(problem)
            break
    return out


@dataclass(frozen=True)
class Row:
    """Summary of one variant over all problems."""

    name: str
    plans: tuple[Plan, ...]

    @property
    def successes(self) -> int:
        return sum(p.success for p in self.plans)

    @property
    def solver_wrong(self) -> int:
        """Solver reported success, certified check failed (would be a clipping path)."""
        return sum(p.status in SOLVED and not p.success for p in self.plans)


def run(problems: list, cfg: PlanConfig) -> tuple[Plan, ...]:
    out = []
    for i, p in enumerate(problems):
        result = plan(p, collision="coal", seed=i, solver=cfg)
        print(
            f"  problem {i:2d}: {result.success!s:5} {result.solve_time:6.2f} s  {result.reason}",
            file=sys.stderr,
            flush=True,
        )
        out.append(result)
    return tuple(out)


def table(rows: list[Row]) -> str:
    both = [all(r.plans[i].success for r in rows) for i in range(len(rows[0].plans))]
    lines = [
        "| variant | verified successes | solver said solved, check failed | median time (s) "
        "| mean time (s) | median iterations | mean path cost (rad², on problems all solved) |",
        "|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        t = [p.solve_time for p in r.plans]
        it = [p.iterations for p in r.plans]
        cost = [p.path_cost for p, b in zip(r.plans, both, strict=True) if b]
        cost_s = f"{np.mean(cost):.2f}" if cost else "–"
        lines.append(
            f"| {r.name} | {r.successes}/{len(r.plans)} | {r.solver_wrong} | {np.median(t):.2f} "
            f"| {np.mean(t):.2f} | {np.median(it):.0f} | {cost_s} |"
        )
    return "\n".join(lines)


def main() -> None:
    p = common.parser("trajopt_ingredients", __doc__)
    p.add_argument("--n", type=int, default=20)
    p.add_argument("--seed", type=int, default=0)
    args = common.parse(p)
    report = common.Report(
        args,
        "Trajectory optimisation: what each ingredient adds (coal constraints, Ipopt)",
        common.first_paragraph(__doc__),
    )
    problems = make_problems(args.n, args.seed)
    rows = []
    for name, cfg in VARIANTS.items():
        print(name, file=sys.stderr, flush=True)
        rows.append(Row(name, run(problems, cfg)))
    report.text(
        f"{args.n} planar7 problems on environment (d), T = 20, margin 0.02 m, success = "
        "certified coal check of the path (conservative advancement) + goal reached. Time = "
        "whole `plan` call (seed search, all Ipopt attempts, verification)."
    )
    report.text(table(rows))
    report.write()


if __name__ == "__main__":
    main()
