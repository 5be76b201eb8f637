"""gdnplan against OMPL's planners on the Table II problems, one validity rule and one certificate.

Usage: python benchmarks/ompl_compare.py --threads 1 [--envs b d fetch] [--problems N] [--first K]
       [--budgets [1 3]] [--planners rrtconnect bitstar aorrtc] [--seeds N] [--kinds rrt …]
       [--out benchmarks/results/…]

Problems: N of the 20 Table II problems of each setting from problem K on (default: all 20)
(:func:`gdnplan.table2.reaching_problems`: (b), (d) and the fetch layouts, seed 0); runs on
disjoint ranges can be merged with ``--render``.
Methods, on every problem in one run:

- gdnplan, ``gp.plan(problem)`` with its defaults (``--seeds`` / ``--kinds`` change the seed
  count and kinds): coal constraints, and GraphDistNet constraints (the shipped weights of the
  setting by name, loaded once per setting);
- OMPL (:func:`gdnplan.ompl_planner.plan_ompl`): each planner + path simplification with each
  time budget of ``--budgets`` (s; none: equal time only) and with "=t", the wall time gdnplan
  (coal) used on that problem (equal time). A budget is OMPL's whole wall time, simplification
  included.

Validity is the same for every method: the problem's certified clearance c
(``Problem.certified_clearance``, the margin) along the whole continuous path. OMPL's states
need coal's proven distance > c and its motions are accepted by gdnplan's own edge certificate
(conservative advancement, :func:`gdnplan.rrt.edge_free`), so OMPL paths are valid by the same
proof that accepts gdnplan's seeds; and every returned path, gdnplan's included, is certified
once more here with :func:`gdnplan.ccd.certify_path` at c and counts as failed unless it
certifies (gdnplan's also needs ``Plan.success``: the goal reached). Metrics: success, median
time (gdnplan: ``Plan.solve_time``; OMPL: planning + simplification), path cost
Σ‖Δq‖² after resampling every path to the problem's T waypoints equally spaced in joint-space
arc length (:func:`gdnplan.path_metrics.resampled_cost`), path length (rad), the certificate's
proven clearance (m), and the paired cost ratio gdnplan / best OMPL per problem (the cheapest
successful OMPL planner at that budget), median over the problems both solved.

Writes the markdown table to ``--out`` (after every problem, so an interrupted run leaves its
rows) and every record to the JSON-lines file beside it.
"""

from __future__ import annotations

import argparse
import datetime
import json
import os
import platform
import shlex
import sys
import time
from dataclasses import replace
from importlib.metadata import version
from pathlib import Path

import numpy as np

import gdnplan as gp
from gdnplan.ccd import certify_path
from gdnplan.ompl_planner import plan_ompl
from gdnplan.path_metrics import path_length, resampled_cost
from gdnplan.table2 import WEIGHTS_ENV, reaching_problems
from gdnplan.trajopt import plan_config

ROOT = Path(__file__).resolve().parent.parent
OUT = ROOT / "benchmarks" / "results" / "ompl_compare.md"
EQUAL = "=t"  # the budget label of "the time gdnplan (coal) used"


def header(command: str) -> str:
    """Markdown lines: command, machine (cpu, cores, python, torch/ompl/coal versions), date.
    (One place, to swap for the shared header helper of benchmarks/.)"""
    cpu = platform.processor() or platform.machine()
    try:
        with open("/proc/cpuinfo") as f:
            cpu = next(ln.split(":", 1)[1].strip() for ln in f if ln.startswith("model name"))
    except (OSError, StopIteration):
        pass
    versions = ", ".join(f"{p} {version(p)}" for p in ("torch", "ompl", "coal", "gdnplan"))
    now = datetime.datetime.now(datetime.UTC).strftime("%Y-%m-%d %H:%M UTC")
    load = ", ".join(f"{x:.1f}" for x in os.getloadavg())
    return (
        f"- command: `{command}`\n"
        f"- machine: {cpu}, {os.cpu_count()} cores, Python {platform.python_version()}, "
        f"{versions}; load average {load}\n"
        f"- date: {now}\n"
    )


def judged(problem, q: np.ndarray, ok: bool) -> dict:
    """Certificate at the problem's certified clearance and the path metrics of q (K, dof)."""
    if len(q) == 0:
        return {"success": False, "cost": None, "length": None, "clearance": None}
    cert = certify_path(problem.scene, q, margin=problem.certified_clearance)
    good = bool(ok and cert.ok)
    return {
        "success": good,
        "cost": resampled_cost(q, problem.waypoints) if good else None,
        "length": path_length(q) if good else None,
        "clearance": float(cert.lower_bound) if cert.ok else None,
    }


def solver(problem, args):
    """gdnplan's settings: the problem's (the defaults), with ``--seeds`` / ``--kinds``."""
    cfg = plan_config(problem)
    seed = cfg.seed
    if args.seeds is not None:
        seed = replace(seed, count=args.seeds)
    if args.kinds is not None:
        seed = replace(seed, kinds=tuple(args.kinds))
    return replace(cfg, seed=seed)


def run_problem(env: str, i: int, problem, model, args) -> list[dict]:
    """Every method on one problem: one record each."""
    out = []
    for name, collision in (("gdnplan coal", "coal"), ("gdnplan GraphDistNet", model)):
        start = time.perf_counter()
        r = gp.plan(problem, collision=collision, solver=solver(problem, args))
        wall = time.perf_counter() - start
        t = float(getattr(r, "solve_time", wall))
        rec = {"env": env, "problem": i, "method": name, "budget": None, "time": t}
        rec["seed"] = None if r.seed is None else r.seed.kind
        out.append(rec | judged(problem, np.asarray(r.q), bool(r.success)))
    equal = max(out[0]["time"], 0.05)
    budgets = [(f"{b:g} s", float(b)) for b in args.budgets] + [(EQUAL, equal)]
    for planner in args.planners:
        for label, budget in budgets:
            r = plan_ompl(
                problem.scene,
                problem.start,
                problem.goal,
                problem.certified_clearance,
                planner,
                budget,
                seed=args.seed,
                lower=problem.lower,
                upper=problem.upper,
            )
            rec = {"env": env, "problem": i, "method": f"OMPL {planner}", "budget": label}
            rec |= {"time": r.time, "status": r.status}  # OMPL's: tells timeouts apart
            out.append(rec | judged(problem, r.path, r.success))
    return out


def _med(values) -> str:
    v = [x for x in values if x is not None]
    return f"{np.median(v):.3g}" if v else "–"


def table(records: list[dict]) -> str:
    """Per setting and method: success, medians; then the paired ratios."""
    lines = [
        "| setting | method | budget | success | median time (s) | median cost (rad²) "
        "| median length (rad) | median / min certified clearance (mm) |",
        "|---|---|---|---|---|---|---|---|",
    ]
    keys = list(dict.fromkeys((r["env"], r["method"], r["budget"]) for r in records))
    for env, method, budget in keys:
        g = [r for r in records if (r["env"], r["method"], r["budget"]) == (env, method, budget)]
        ok = [r for r in g if r["success"]]
        clear = [1000 * r["clearance"] for r in ok]
        lines.append(
            f"| {env} | {method} | {budget or '–'} | {len(ok)}/{len(g)} "
            f"| {_med(r['time'] for r in g)} | {_med(r['cost'] for r in ok)} "
            f"| {_med(r['length'] for r in ok)} "
            f"| {_med(clear)} / {min(clear):.3g} |"
            if clear
            else f"| {env} | {method} | {budget or '–'} | 0/{len(g)} "
            f"| {_med(r['time'] for r in g)} | – | – | – |"
        )
    return "\n".join(lines) + "\n\n" + ratios(records)


def _ratio(q: list[float], lengths: list[float]) -> str:
    """'median [n] | max | wins/n | median length ratio' of the paired ratios q."""
    if not q:
        return "– [0] | – | 0/0 | –"
    wins = sum(x <= 1.0 for x in q)
    return (
        f"{np.median(q):.3f} [{len(q)}] | {max(q):.3g} | {wins}/{len(q)} | {np.median(lengths):.3f}"
    )


def _paired(ours: dict, best: dict, key: str) -> list[float]:
    return [ours[p][key] / best[p][key] for p in ours if p in best and best[p][key] > 0]


def ratios(records: list[dict]) -> str:
    """Median over problems of cost(gdnplan) / min over OMPL planners of cost, per budget."""
    lines = [
        "Paired cost ratio gdnplan / best OMPL planner at each budget (median over the problems "
        "both solved [n]; ≤ 1: gdnplan is cheaper; wins: problems with ratio ≤ 1):",
        "",
        "| setting | gdnplan | OMPL budget | median ratio [n] | max ratio | wins "
        "| median length ratio |",
        "|---|---|---|---|---|---|---|",
    ]
    budgets = [*dict.fromkeys(r["budget"] for r in records if r["budget"]), "any"]
    for env in dict.fromkeys(r["env"] for r in records):
        mine = [r for r in records if r["env"] == env and r["success"]]
        for method in ("gdnplan coal", "gdnplan GraphDistNet"):
            ours = {r["problem"]: r for r in mine if r["method"] == method}
            for budget in budgets:
                best: dict[int, dict] = {}  # the cheapest OMPL path of each problem
                for r in mine:
                    if r["method"].startswith("OMPL") and budget in (r["budget"], "any"):
                        if r["cost"] < best.get(r["problem"], {"cost": np.inf})["cost"]:
                            best[r["problem"]] = r
                q, lengths = _paired(ours, best, "cost"), _paired(ours, best, "length")
                lines.append(f"| {env} | {method} | {budget} | {_ratio(q, lengths)} |")
        coal = {r["problem"]: r for r in mine if r["method"] == "gdnplan coal"}
        gdn = {r["problem"]: r for r in mine if r["method"] == "gdnplan GraphDistNet"}
        q, lengths = _paired(gdn, coal, "cost"), _paired(gdn, coal, "length")
        lines.append(f"| {env} | GraphDistNet / coal | (gdnplan coal) | {_ratio(q, lengths)} |")
    return "\n".join(lines) + "\n"


NOTES = """
Notes: every path (gdnplan's and OMPL's) is certified here with `gdnplan.ccd.certify_path` at
the problem's certified clearance (the margin: 2 cm on (b) and (d), 1 cm on fetch) and counts
as failed unless proven; OMPL's motion validator is gdnplan's edge certificate, so its paths
are certified as they are built. Cost: Σ‖Δq‖² after resampling to the problem's T waypoints
(20; fetch 30) equally spaced in joint-space arc length (≈ length² / (T − 1)); medians over the
successful runs; the length ratio is that of the same pairs (the cheapest OMPL path's length).
Budget "=t": the wall time gdnplan with coal constraints used on that problem (`Plan.solve_time`:
seeds, solves, certificates). An OMPL budget is its whole wall time: set-up, planning (80 %
of the budget for an anytime planner) and simplification in the rest; OMPL's time column
includes the final certificate. Times on a shared CPU.
"""


def write(records: list[dict], head: str, out: Path) -> None:
    """The markdown: title, ``head`` (:func:`header`'s lines), tables, notes."""
    out.parent.mkdir(parents=True, exist_ok=True)
    text = "# gdnplan vs OMPL on the Table II problems\n\n" + head + "\n"
    out.write_text(text + table(records) + NOTES)


def check_args(args: argparse.Namespace) -> None:
    """Every flag checked before any work (InputError naming it): an unknown --envs name raised
    KeyError, --budgets nan or -1 and --planners or --kinds unknown to OMPL or gdnplan raised
    tracebacks after gdnplan's solves of the first problem had run, and --threads 0 raised
    torch's RuntimeError; --problems 0 or --first -5 wrote an empty table."""
    from gdnplan.errors import InputError
    from gdnplan.files import check_output_path
    from gdnplan.limits import check_int, check_number
    from gdnplan.models.threads import check_threads
    from gdnplan.ompl_planner import MAX_OMPL_SEED, MAX_TIME, PLANNERS
    from gdnplan.trajopt import SeedConfig

    check_threads(args.threads, "--threads", default=False)
    for env in args.envs:
        if env not in WEIGHTS_ENV:
            raise InputError(f"--envs: unknown {env!r}; choose from {sorted(WEIGHTS_ENV)}")
    check_int(args.problems, "--problems", 1)
    check_int(args.first, "--first", 0)
    for budget in args.budgets:
        if check_number(budget, "--budgets", strict=True) > MAX_TIME:
            raise InputError(f"--budgets: {budget:g} s is over OMPL's limit {MAX_TIME:g} s")
    for planner in args.planners:
        if planner not in PLANNERS:
            raise InputError(f"--planners: unknown {planner!r}; choose from {sorted(PLANNERS)}")
    check_int(args.seed, "--seed", 0, MAX_OMPL_SEED)
    try:
        SeedConfig(count=args.seeds, kinds=tuple(args.kinds or SeedConfig.kinds))
    except InputError as e:
        raise InputError(f"--seeds/--kinds: {e}") from e
    check_output_path(args.out, (".md",), "--out")
    if args.render is not None and not args.render.is_file():
        raise InputError(f"--render: {str(args.render)!r} is no records file (.jsonl)")


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--threads", type=int, default=1, help="torch threads")
    parser.add_argument("--envs", nargs="+", default=["b", "d", "fetch"])
    parser.add_argument("--problems", type=int, default=20)
    parser.add_argument("--first", type=int, default=0, help="index of the first problem")
    parser.add_argument("--budgets", nargs="*", type=float, default=[1.0, 3.0])
    parser.add_argument("--planners", nargs="+", default=["rrtconnect", "bitstar", "aorrtc"])
    parser.add_argument("--seed", type=int, default=0, help="OMPL's random seed")
    parser.add_argument("--seeds", type=int, help="gdnplan's seed count (default: its own)")
    parser.add_argument("--kinds", nargs="+", help="gdnplan's seed kinds (default: its own)")
    parser.add_argument("--out", type=Path, default=OUT)
    parser.add_argument(
        "--render", type=Path, help="only rewrite --out from this records file (.jsonl)"
    )
    args = parser.parse_args(argv)
    try:
        check_args(args)
    except gp.GdnplanError as e:
        parser.error(str(e))  # exit status 2, no traceback
    if args.render:
        records = [json.loads(ln) for ln in args.render.read_text().splitlines() if ln]
        old = args.out.read_text().splitlines() if args.out.exists() else []
        keys = ("- command: ", "- machine: ", "- date: ")
        write(records, "".join(ln + "\n" for ln in old if ln.startswith(keys)), args.out)
        return
    import torch

    from gdnplan.models import set_inference_threads

    torch.set_num_threads(args.threads)
    set_inference_threads(args.threads)
    given = sys.argv[1:] if argv is None else argv
    command = "python benchmarks/ompl_compare.py " + shlex.join(given)
    jsonl = args.out.with_suffix(".jsonl")
    jsonl.parent.mkdir(parents=True, exist_ok=True)
    jsonl.write_text("")
    records: list[dict] = []
    head = header(command)  # the date the run started
    for env in args.envs:
        model = gp.load_model(WEIGHTS_ENV[env])
        problems = reaching_problems(env, n=args.first + args.problems)[args.first :]
        for i, problem in enumerate(problems, start=args.first):
            recs = run_problem(env, i, problem, model, args)
            records += recs
            with jsonl.open("a") as f:
                f.writelines(json.dumps(r) + "\n" for r in recs)
            write(records, head, args.out)
            summary = ", ".join(
                f"{r['method'].split()[-1]} {r['budget'] or ''}: "
                + ("-" if r["cost"] is None else f"{r['cost']:.3g}")
                for r in recs
            )
            print(f"{env} #{i}: {summary}", flush=True)
    print(table(records))


if __name__ == "__main__":
    main()
