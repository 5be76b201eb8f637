"""GraphDistNet vs coal: seconds for a batch of configurations, measured side by side in one run.

Usage: python benchmarks/inference.py [--n 5000] [--repeats 3] [--envs a b c d e fetch]
[--threads 1] [--weights weights/]

For each scene with weights (``<weights>/<env>.safetensors``, shipped ones by default; the UR5e
``fetch`` scene uses ``ur5e.safetensors``), on one scene (seed 0) and the same n uniformly random
configurations: coal distance and distance + exact gradient (bounding-circle broad phase,
batches split over all cores by processes) and GraphDistNet distance and distance + ∂d̂/∂q
(float32, ``--threads`` torch threads), best of the repeats, after one warm-up call each. Also
the achieved GFLOP/s of the GraphDistNet distance pass (matmul FLOPs counted by torch's
FlopCounterMode) against the GFLOP/s of a 2048² float32 matmul with the same threads, and the
machine, date and load average (other jobs may share the CPU: compare ratios, not seconds).
"""

from __future__ import annotations

import argparse
import datetime
import os
import subprocess
import time
from collections.abc import Callable

import torch
from torch.utils.flop_counter import FlopCounterMode

import gdnplan as gp
from gdnplan import distance
from gdnplan.assets import default_weights


def best_time(fn: Callable[[], object], repeats: int) -> float:
    """Shortest wall time (s) of ``repeats`` calls of ``fn``."""
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        fn()
        times.append(time.perf_counter() - start)
    return min(times)


def matmul_gflops(size: int = 2048, repeats: int = 5) -> float:
    """GFLOP/s of a float32 (size × size) matmul: the practical peak of this CPU."""
    a, b = torch.randn(size, size), torch.randn(size, size)
    a @ b
    seconds = best_time(lambda: a @ b, repeats)
    return 2 * size**3 / seconds / 1e9


def forward_flops(model, scene: gp.Scene, q) -> int:
    """Matmul FLOPs of ``model.distance(scene, q)``."""
    with FlopCounterMode(display=False) as counter:
        model.distance(scene, q)
    return counter.get_total_flops()


def machine() -> str:
    """CPU model name (lscpu), core count and torch version."""
    out = subprocess.run(["lscpu"], capture_output=True, text=True).stdout
    name = next((ln.split(":", 1)[1].strip() for ln in out.splitlines() if "Model name" in ln), "?")
    return f"{name}, {os.cpu_count()} cores, torch {torch.__version__}"


def row(env: str, n: int, repeats: int, peak: float) -> str:
    """One table row: seconds of coal and GraphDistNet for n configurations of scene ``env``."""
    scene = gp.make_scene(env, seed=0)
    q = scene.robot.sample(n, seed=0)
    model = gp.load_model(default_weights(scene))
    distance.checker(scene)
    calls = {
        "coal d": lambda: gp.signed_distance(scene, q),
        "coal d+grad": lambda: gp.signed_distance_and_grad(scene, q),
        "GDN d": lambda: model.distance(scene, q),
        "GDN d+grad": lambda: model.distance_and_grad(scene, q),
    }
    for fn in calls.values():  # warm-up: caches, allocator, lazy initialisation
        fn()
    t = {name: best_time(fn, repeats) for name, fn in calls.items()}
    gflops = forward_flops(model, scene, q) / t["GDN d"] / 1e9
    seconds = " | ".join(f"{s:.3f}" for s in t.values())
    ratios = f"{t['GDN d'] / t['coal d']:.1f}× | {t['GDN d+grad'] / t['coal d+grad']:.1f}×"
    share = f"{gflops:.1f} ({100 * gflops / peak:.0f} %)"
    return f"| {env} ({scene.robot.name}) | {seconds} | {ratios} | {share} |"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--n", type=int, default=5000)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--envs", nargs="+", default=["a", "b", "c", "d", "e", "fetch"])
    parser.add_argument("--threads", type=int, default=1, help="torch intra-op threads")
    args = parser.parse_args()
    torch.set_num_threads(args.threads)
    peak = matmul_gflops()
    now = datetime.datetime.now(datetime.UTC).strftime("%Y-%m-%d %H:%M UTC")
    print(f"machine: {machine()}; torch threads {args.threads}; n = {args.n}; {now}")
    print("weights: the shipped default of each scene (gdnplan.assets.default_weights)")
    print(f"load average at start: {os.getloadavg()}")
    print(f"float32 matmul peak ({args.threads} threads): {peak:.1f} GFLOP/s")
    print(
        "| env (robot) | coal d (s) | coal d+grad (s) | GDN d (s) | GDN d+grad (s) "
        "| GDN/coal d | GDN/coal d+grad | GDN d GFLOP/s (share of peak) |"
    )
    print("|---|---|---|---|---|---|---|---|")
    for env in args.envs:
        print(row(env, args.n, args.repeats, peak), flush=True)
    print(f"load average at end: {os.getloadavg()}")


if __name__ == "__main__":
    main()
