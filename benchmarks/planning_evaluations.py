"""Where a Table II solve's work goes: constraint evaluations, Ipopt iterations, time, cost.

Plans the reaching problems of ``gdnplan.table2.reaching_problems(setting)`` (``--setting`` d, b
or fetch; default d; RRT seed 0 for every problem) with Ipopt and one or more collision models
(``--model GraphDistNet coal``: side by side, the models in turn on each problem, in alternating
order; any other name is GraphDistNet weights by path or shipped name), after one warm-up
plan each, and reports per problem and model: certified or not, wall time (s), the process's CPU
time (s: the work, however busy the shared machine), batched constraint evaluations (model
passes), Ipopt iterations and path cost (rad²), then the medians and, for two models, the ratios
of their median wall and CPU times. Evaluation and iteration counts are deterministic for a
given ``--threads`` (a different count changes the float32 sums and so Ipopt's path), so solver
settings can be compared on a busy machine by counts; compare times only within one run.

    python benchmarks/planning_evaluations.py --threads 1 --model GraphDistNet
    python benchmarks/planning_evaluations.py --threads 1 --model GraphDistNet coal --setting fetch
    python benchmarks/planning_evaluations.py --threads 1 --setting fetch \
        --model runs/ur5e-one-way.safetensors coal   # other weights
    python benchmarks/planning_evaluations.py --threads 1 --model GraphDistNet coal \
        --setting fetch --first 10 --n 10   # problems 10-19 (halves run in parallel)
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
import time

import common
import numpy as np

import gdnplan as gp
from gdnplan.errors import GdnplanError
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


def factory(model: str, setting: str):
    """problem → collision model: GraphDistNet (the setting's shipped weights) or coal, else
    GraphDistNet weights by path or shipped name (``gp.load_model``'s error names a bad one)."""
    if model in ("GraphDistNet", "coal"):
        return model_factory(model, setting)
    loaded = gp.load_model(model)
    return lambda problem: loaded


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
    p.add_argument(
        "--model",
        nargs="+",
        default=["GraphDistNet"],
        help="collision model(s): GraphDistNet, coal, or GraphDistNet weights by path or "
        "shipped name; several run side by side, problem by problem",
    )
    p.add_argument("--setting", default="d", choices=list(SETTINGS))
    p.add_argument("--n", type=int, default=20)
    p.add_argument("--first", type=int, default=0, help="index of the first problem")
    p.add_argument("--ipopt", nargs="*", default=[], metavar="NAME=VALUE")
    p.add_argument("--set", nargs="*", default=[], metavar="TABLE.KEY=VALUE")
    args = common.parse(p)
    cfg = plan_config(args.set, args.ipopt)
    models = list(dict.fromkeys(args.model))
    try:
        factories = {m: factory(m, args.setting) for m in models}
    except GdnplanError as e:
        p.error(f"--model: {e}")
    problems = reaching_problems(args.setting)[args.first : args.first + args.n]
    report = common.Report(
        args, "Planning: evaluations per Table II solve", common.first_paragraph(__doc__)
    )
    report.text(
        f"{' and '.join(models)} constraints, setting ({args.setting}), {len(problems)} "
        f"problems from {args.first} (models in turn per problem, their order alternating); "
        f"options: ipopt={cfg.optimizer.options}, set={args.set}."
    )
    for m in models:  # warm-up: imports, compilation
        gp.plan(problems[0], collision=factories[m](problems[0]), solver=cfg)
    table = report.table(
        "problem",
        "constraints",
        "certified",
        "time (s)",
        "CPU (s)",
        "evaluations",
        "iterations",
        "path cost (rad²)",
    )
    rows: dict[str, list] = {m: [] for m in models}
    for i, problem in enumerate(problems):
        for m in models if i % 2 == 0 else models[::-1]:
            cpu = time.process_time()
            r = gp.plan(problem, collision=factories[m](problem), solver=cfg)
            cpu = time.process_time() - cpu
            rows[m].append((r.success, r.solve_time, cpu, r.model_calls, r.iterations, r.path_cost))
            table.add(
                args.first + i,
                m,
                r.success,
                f"{r.solve_time:.2f}",
                f"{cpu:.2f}",
                r.model_calls,
                r.iterations,
                f"{r.path_cost:.3f}",
            )
    stats = {m: [np.array(c) for c in zip(*rows[m], strict=True)] for m in models}
    for m, (ok, t, cpu, calls, iters, cost) in stats.items():
        report.text(
            f"**{m} ({args.setting}): {ok.sum()}/{len(ok)} certified, "
            f"median time {np.median(t):.2f} s (CPU {np.median(cpu):.2f} s), "
            f"median evaluations {np.median(calls):.1f}, "
            f"median iterations {np.median(iters):.1f}, mean path cost {cost.mean():.3f} rad².**"
        )
    if len(models) > 1:
        (a, sa), (b, sb) = list(stats.items())[:2]
        both = sa[0] & sb[0]
        report.text(
            f"**{a} / {b}: median time {np.median(sa[1]) / np.median(sb[1]):.2f}× "
            f"(certified {sa[0].sum()} vs {sb[0].sum()}); on the {both.sum()} problems both "
            f"certified {np.median(sa[1][both]) / np.median(sb[1][both]):.2f}×, median of the "
            f"per-problem ratios {np.median(sa[1][both] / sb[1][both]):.2f}×; median CPU time "
            f"{np.median(sa[2]) / np.median(sb[2]):.2f}× (the process's CPU seconds: the work, "
            "whatever else ran on the machine).**"
        )
    report.write()


if __name__ == "__main__":
    main()
