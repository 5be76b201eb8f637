"""GraphDistNet vs coal: seconds for a batch of configurations, measured side by side in one run.

Usage: python benchmarks/inference.py [--n 5000] [--repeats 3] [--envs a b c d e] [--device cpu]

For each environment with shipped weights (``weights/<env>.safetensors``), on one scene (seed 0)
and the same n uniformly random configurations: coal distance and distance + exact gradient
(broad phase, all cores) and GraphDistNet distance and distance + ∂d̂/∂q (float32, all cores),
best of the repeats. Also the achieved GFLOP/s of the GraphDistNet forward pass (FLOPs counted
by torch's FlopCounterMode) against the GFLOP/s of a large float32 matmul on the same machine.
"""

from __future__ import annotations

import argparse
import os
import platform
import time
from pathlib import Path

import torch
from torch.utils.flop_counter import FlopCounterMode

import gdnplan as gp
from gdnplan import distance

WEIGHTS = Path(__file__).resolve().parent.parent / "weights"


def best_time(fn, repeats: int) -> float:
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        fn()
        times.append(time.perf_counter() - start)
    return min(times)


def matmul_gflops(size: int = 2048, repeats: int = 5) -> float:
    """GFLOP/s of a float32 (size × size) matmul: the practical peak of this CPU."""
    a, b = torch.randn(size, size), torch.randn(size, size)
    seconds = best_time(lambda: a @ b, repeats)
    return 2 * size**3 / seconds / 1e9


def forward_flops(model, scene, q) -> int:
    with FlopCounterMode(display=False) as counter:
        model.distance(scene, q)
    return counter.get_total_flops()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--n", type=int, default=5000)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--envs", nargs="+", default=["a", "b", "c", "d", "e"])
    args = parser.parse_args()
    torch.set_num_threads(os.cpu_count() or 1)
    peak = matmul_gflops()
    machine = platform.processor() or platform.machine()
    print(f"machine: {machine}, {os.cpu_count()} cores, torch {torch.__version__}, n = {args.n}")
    print(f"float32 matmul peak: {peak:.1f} GFLOP/s")
    print(
        "| env | coal d (s) | coal d+grad (s) | GDN d (s) | GDN d+grad (s) "
        "| GDN/coal (d+grad) | GDN GFLOP/s (share of peak) |"
    )
    print("|---|---|---|---|---|---|---|")
    for env in args.envs:
        path = WEIGHTS / f"{env}.safetensors"
        if not path.exists():
            print(f"| {env} | (no weights at {path.name}) |||||")
            continue
        scene = gp.make_scene(env, seed=0)
        q = scene.robot.sample(args.n, seed=0)
        model = gp.load_model(path)
        distance.checker(scene)
        model.distance(scene, q[:10])  # warm-up
        t_cd = best_time(lambda s=scene, q=q: gp.signed_distance(s, q), args.repeats)
        t_cg = best_time(lambda s=scene, q=q: gp.signed_distance_and_grad(s, q), args.repeats)
        t_gd = best_time(lambda s=scene, q=q, m=model: m.distance(s, q), args.repeats)
        t_gg = best_time(lambda s=scene, q=q, m=model: m.distance_and_grad(s, q), args.repeats)
        gflops = forward_flops(model, scene, q) / t_gd / 1e9
        print(
            f"| {env} | {t_cd:.3f} | {t_cg:.3f} | {t_gd:.3f} | {t_gg:.3f} | {t_gg / t_cg:.1f}× "
            f"| {gflops:.1f} ({100 * gflops / peak:.0f} %) |"
        )


if __name__ == "__main__":
    main()
