"""Seconds for 5 000 configurations of coal signed distance (and + exact gradient) per environment.

Usage: python benchmarks/coal_distance.py [--n 5000] [--repeats 3]
Prints a markdown table: one core vs all cores, side by side in one run (best of the repeats).
"""

from __future__ import annotations

import argparse
import os
import platform
import time

import gdnplan as gp
from gdnplan import distance

ENVS = ["a", "b", "c", "d", "e"]


def best_time(fn, repeats: int) -> float:
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        fn()
        times.append(time.perf_counter() - start)
    return min(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--n", type=int, default=5000)
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    machine = platform.processor() or platform.machine()
    print(f"machine: {machine}, {os.cpu_count()} cores; n = {args.n}")
    print(
        "| env | distance, 1 core (s) | distance + grad, 1 core (s) "
        "| distance + grad, all cores (s) | µs / config (all cores) |"
    )
    print("|---|---|---|---|---|")
    for env in ENVS:
        scene = gp.make_scene(env, seed=0)
        q = scene.robot.sample(args.n, seed=0)
        distance.checker(scene)  # build coal shapes outside the timing
        distance.PARALLEL_MIN_BATCH = 10**12
        t_d = best_time(lambda s=scene, q=q: gp.signed_distance(s, q), args.repeats)
        t_g = best_time(lambda s=scene, q=q: gp.signed_distance_and_grad(s, q), args.repeats)
        distance.PARALLEL_MIN_BATCH = 2000
        t_p = best_time(lambda s=scene, q=q: gp.signed_distance_and_grad(s, q), args.repeats)
        print(f"| {env} | {t_d:.3f} | {t_g:.3f} | {t_p:.3f} | {1e6 * t_p / args.n:.1f} |")


if __name__ == "__main__":
    main()
