"""Where a Table II solve's work goes: constraint evaluations, Ipopt iterations, time, cost.

Plans the 20 reaching problems of ``gdnplan.table2.reaching_problems(setting)`` (``--setting``
d, b or fetch; default d) with Ipopt and one collision model, and prints per problem:
certified or not, wall time (s), batched constraint evaluations (model passes), Ipopt
iterations and path cost (rad²), then the medians.
Evaluation and iteration counts are deterministic for a given ``--threads`` (torch threads,
default 1; a different count changes the float32 sums and so Ipopt's path), so solver settings
can be compared on a busy machine by counts; compare times only within one run.

    .venv/bin/python benchmarks/planning_evaluations.py --model GraphDistNet
    .venv/bin/python benchmarks/planning_evaluations.py --model coal \
        --ipopt limited_memory_initialization=scalar1 --set obj_change_tol=1e-4
    .venv/bin/python benchmarks/planning_evaluations.py --setting fetch --set interpolated=3

``--ipopt name=value`` sets an extra Ipopt option (``TrajoptOptions.ipopt``), ``--set
name=value`` a ``TrajoptOptions`` field (values parsed as JSON, else kept as strings).
"""

from __future__ import annotations

import argparse
import json
from dataclasses import replace

import numpy as np
import torch

import gdnplan as gp
from gdnplan.table2 import SETTINGS, model_factory, reaching_problems
from gdnplan.trajopt import TrajoptOptions


def _pairs(items: list[str]) -> dict:
    out = {}
    for item in items:
        key, _, text = item.partition("=")
        try:
            out[key] = json.loads(text)
        except json.JSONDecodeError:
            out[key] = text
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--model", default="GraphDistNet", choices=["GraphDistNet", "coal"])
    parser.add_argument("--setting", default="d", choices=list(SETTINGS))
    parser.add_argument("--n", type=int, default=20)
    parser.add_argument("--ipopt", nargs="*", default=[], metavar="NAME=VALUE")
    parser.add_argument("--set", nargs="*", default=[], metavar="FIELD=VALUE")
    parser.add_argument("--threads", type=int, default=1)
    args = parser.parse_args()
    torch.set_num_threads(args.threads)
    opts = replace(TrajoptOptions(ipopt=_pairs(args.ipopt)), **_pairs(args.set))
    model_of = model_factory(args.model, args.setting)
    problems = reaching_problems(args.setting)[: args.n]
    gp.plan(problems[0], collision=model_of(problems[0]), options=opts)  # warm-up: imports
    print("| problem | certified | time (s) | evaluations | iterations | path cost (rad²) |")
    print("|---|---|---|---|---|---|")
    rows = []
    for i, problem in enumerate(problems):
        r = gp.plan(problem, collision=model_of(problem), options=opts)
        rows.append((r.success, r.solve_time, r.model_calls, r.iterations, r.path_cost))
        print(
            f"| {i} | {r.success} | {r.solve_time:.2f} | {r.model_calls} | {r.iterations} "
            f"| {r.path_cost:.3f} |",
            flush=True,
        )
    ok, t, calls, iters, cost = (np.array(c) for c in zip(*rows, strict=True))
    print(
        f"\n{args.model} ({args.setting}): {ok.sum()}/{len(ok)} certified, "
        f"median time {np.median(t):.2f} s, "
        f"median evaluations {np.median(calls):.1f}, median iterations {np.median(iters):.1f}, "
        f"mean path cost {cost.mean():.3f} rad² (options: ipopt={opts.ipopt}, set={args.set}, "
        f"threads={args.threads})"
    )


if __name__ == "__main__":
    main()
