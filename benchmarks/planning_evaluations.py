"""Where a Table II solve's work goes: constraint evaluations, Ipopt iterations, time, cost.

Plans the reaching problems of ``gdnplan.table2.reaching_problems(setting)`` (``--setting``
d, b or fetch; default d; RRT seed 0 for every problem) with Ipopt and one collision model,
after one warm-up plan, and reports per problem: certified or not, wall time (s), batched
constraint evaluations (model passes), Ipopt iterations and path cost (rad²), then the medians.
Evaluation and iteration counts are deterministic for a given ``--threads`` (a different count
changes the float32 sums and so Ipopt's path), so solver settings can be compared on a busy
machine by counts; compare times only within one run.

    python benchmarks/planning_evaluations.py --threads 1 --model GraphDistNet
    python benchmarks/planning_evaluations.py --threads 1 --model coal \
        --ipopt limited_memory_initialization=scalar1 --set ipopt.obj_change_tol=1e-4 \
        --out benchmarks/results/planning_evaluations_coal_scalar1.md
    python benchmarks/planning_evaluations.py --threads 1 --setting fetch \
        --set ipopt.interpolated=3 refine.rounds=2 seed.rrt_step=0.3

``--set table.key=value`` sets one planner setting, named as in a problem file's tables
(``seed.*``: :class:`gdnplan.SeedConfig`, ``refine.*``: ``RefineConfig``, ``ipopt.*``:
``IpoptConfig``; e.g. ``refine.rounds=2``); a bare old ``TrajoptOptions`` field name
(``obj_change_tol=1e-4``, ``refine_rounds=2``) is taken to its new home
(:data:`gdnplan.trajopt.options.OLD_KEYS`). ``--ipopt name=value`` sets an extra Ipopt option
(``IpoptConfig.options``). Values are parsed as JSON, else kept as strings; the settings
are checked as a problem file's are (one line naming the setting on a bad one).
"""

from __future__ import annotations

import json

import common
import numpy as np

import gdnplan as gp
from gdnplan.table2 import SETTINGS, model_factory, reaching_problems
from gdnplan.trajopt import OLD_KEYS, PlanConfig
from gdnplan.trajopt.problem_file import plan_config_from_tables

TABLES = ("seed", "refine", "ipopt")  # --set's tables (the script runs Ipopt)


def _pairs(items: list[str]) -> dict:
    out = {}
    for item in items:
        key, _, text = item.partition("=")
        try:
            out[key] = json.loads(text)
        except json.JSONDecodeError:
            out[key] = text
    return out


def plan_config(settings: list[str], ipopt_options: list[str]) -> PlanConfig:
    """The PlanConfig of ``--set table.key=value`` (or an old bare field name) and ``--ipopt
    name=value`` items, checked like a problem file's tables (exits with one line if not)."""
    tables: dict[str, dict] = {"ipopt": {}}
    for name, value in _pairs(settings).items():
        table, _, key = name.rpartition(".")
        if not table and OLD_KEYS.get(key) is not None:
            table, key = OLD_KEYS[key]
        if table not in TABLES:
            raise SystemExit(f"--set {name}: name a setting as table.key, table one of {TABLES}")
        tables.setdefault(table, {})[key] = value
    if ipopt_options:
        tables["ipopt"]["options"] = {**tables["ipopt"].get("options", {}), **_pairs(ipopt_options)}
    try:
        return plan_config_from_tables(tables)
    except gp.GdnplanError as e:
        raise SystemExit(f"--set: {e}") from e


def main() -> None:
    p = common.parser("planning_evaluations", __doc__)
    p.add_argument("--model", default="GraphDistNet", choices=["GraphDistNet", "coal"])
    p.add_argument("--setting", default="d", choices=list(SETTINGS))
    p.add_argument("--n", type=int, default=20)
    p.add_argument("--ipopt", nargs="*", default=[], metavar="NAME=VALUE")
    p.add_argument("--set", nargs="*", default=[], metavar="TABLE.KEY=VALUE")
    args = common.parse(p)
    cfg = plan_config(args.set, args.ipopt)
    model_of = model_factory(args.model, args.setting)
    problems = reaching_problems(args.setting)[: args.n]
    report = common.Report(
        args, "Planning: evaluations per Table II solve", common.first_paragraph(__doc__)
    )
    report.text(
        f"{args.model} constraints, setting ({args.setting}), {len(problems)} problems; "
        f"options: ipopt={cfg.optimizer.options}, set={args.set}."
    )
    gp.plan(problems[0], collision=model_of(problems[0]), solver=cfg)  # warm-up: imports
    table = report.table(
        "problem", "certified", "time (s)", "evaluations", "iterations", "path cost (rad²)"
    )
    rows = []
    for i, problem in enumerate(problems):
        r = gp.plan(problem, collision=model_of(problem), solver=cfg)
        rows.append((r.success, r.solve_time, r.model_calls, r.iterations, r.path_cost))
        table.add(
            i, r.success, f"{r.solve_time:.2f}", r.model_calls, r.iterations, f"{r.path_cost:.3f}"
        )
    ok, t, calls, iters, cost = (np.array(c) for c in zip(*rows, strict=True))
    report.text(
        f"**{args.model} ({args.setting}): {ok.sum()}/{len(ok)} certified, "
        f"median time {np.median(t):.2f} s, median evaluations {np.median(calls):.1f}, "
        f"median iterations {np.median(iters):.1f}, mean path cost {cost.mean():.3f} rad².**"
    )
    report.write()


if __name__ == "__main__":
    main()
