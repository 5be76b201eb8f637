"""GraphDistNet distance + gradient under 1 torch thread vs torch's default, side by side.

Usage: python benchmarks/threads.py [--env d] [--batch 64 1000] [--rounds 30] [--plans 2]

On scene ``env`` (seed 0) with its shipped weights, ``distance_and_grad`` of ``batch`` random
configurations (64: a planner-sized call) runs under three settings, interleaved call by call
(so a change of load hits all three alike), after a warm-up:

- ``default``: the model's ``threads`` set to torch's default count (one per core);
- ``1 thread``: torch's global count 1 and the model's 1 (no switching);
- ``1 thread, switched``: the caller at torch's default, the model at 1 (the library default):
  :func:`gdnplan.models.threads.torch_threads` sets 1 and restores the default on every call.

Then the whole planner, where the network calls alternate with Ipopt, CasADi and coal:
``gdnplan.plan`` of ``problems/planar7_d.toml`` with GraphDistNet, the inference threads at
torch's default and at 1, interleaved, ``--plans`` times each (0: skip).

Prints the median seconds, default / 1 thread, and the cost of switching, with the machine,
date and load average (other jobs may share the CPU: compare ratios, not seconds).
"""

from __future__ import annotations

import argparse
import datetime
import os
import platform
import statistics
import time
from pathlib import Path

import torch

import gdnplan as gp
from gdnplan.models import set_inference_threads

ROOT = Path(__file__).resolve().parent.parent
WEIGHTS = ROOT / "weights"


def timed(fn) -> float:
    start = time.perf_counter()
    fn()
    return time.perf_counter() - start


def measure(env: str, batch: int, rounds: int, default: int) -> dict[str, float]:
    """Median seconds of one ``distance_and_grad`` call of ``batch`` configurations."""
    scene = gp.make_scene(env, seed=0)
    model = gp.load_model(WEIGHTS / f"{env}.safetensors")
    q = scene.robot.sample(batch, seed=0)

    def call(model_threads: int, caller_threads: int):
        def run() -> None:
            torch.set_num_threads(caller_threads)
            model.threads = model_threads
            model.distance_and_grad(scene, q)

        return run

    settings = {
        "default": call(default, default),
        "1 thread": call(1, 1),
        "1 thread, switched": call(1, default),
    }
    for fn in settings.values():  # warm-up: the scene's graphs, allocator, thread pools
        fn()
    times: dict[str, list[float]] = {name: [] for name in settings}
    for _ in range(rounds):
        for name, fn in settings.items():
            times[name].append(timed(fn))
    torch.set_num_threads(default)
    return {name: statistics.median(t) for name, t in times.items()}


def measure_plans(rounds: int, default: int) -> dict[int, float]:
    """Median seconds of ``gdnplan.plan`` (planar7_d, GraphDistNet) per inference thread count."""
    problem = gp.Problem.from_toml(ROOT / "problems" / "planar7_d.toml")
    gp.plan(problem, collision="graphdistnet")  # warm-up: torch, weights
    times: dict[int, list[float]] = {default: [], 1: []}
    for _ in range(rounds):
        for n, t in times.items():
            set_inference_threads(n)
            t.append(timed(lambda: gp.plan(problem, collision="graphdistnet")))
    set_inference_threads(1)
    return {n: statistics.median(t) for n, t in times.items()}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--env", default="d")
    parser.add_argument("--batch", type=int, nargs="+", default=[64, 1000])
    parser.add_argument("--rounds", type=int, default=30)
    parser.add_argument("--plans", type=int, default=2, help="plans per setting (0: none)")
    args = parser.parse_args()
    default = torch.get_num_threads()
    now = datetime.datetime.now(datetime.UTC).strftime("%Y-%m-%d %H:%M UTC")
    cpu = platform.processor() or platform.machine()
    print(f"machine: {platform.node()}, {cpu}, {os.cpu_count()} cores, torch {torch.__version__}")
    print(f"torch default threads: {default}; env {args.env}; {args.rounds} rounds; {now}")
    print(f"load average at start: {os.getloadavg()}")
    print(
        f"| batch | default ({default} threads) (s) | 1 thread (s) | 1 thread, switched (s) "
        "| default / 1 thread | switched / 1 thread |"
    )
    print("|---|---|---|---|---|---|")
    for batch in args.batch:
        t = measure(args.env, batch, args.rounds, default)
        one = t["1 thread"]
        print(
            f"| {batch} | {t['default']:.4f} | {one:.4f} | {t['1 thread, switched']:.4f} "
            f"| {t['default'] / one:.2f}× | {t['1 thread, switched'] / one:.2f}× |",
            flush=True,
        )
    if args.plans:
        t = measure_plans(args.plans, default)
        print(
            f"| plan planar7_d | {t[default]:.2f} | {t[1]:.2f} | (the library default) "
            f"| {t[default] / t[1]:.2f}× | |"
        )
    print(f"load average at end: {os.getloadavg()}")


if __name__ == "__main__":
    main()
