"""coal signed distance (and + exact gradient) for a batch of configurations, per environment.

On each environment's scene (seed 0) and n uniformly random configurations (seed 0): coal's
signed distance on one core, distance + exact gradient on one core, and distance + gradient over
all cores (``gdnplan.distance`` splits batches of at least ``PARALLEL_MIN_BATCH`` over forked
workers), side by side in one run: best of the repeats after one warm-up call each.

    python benchmarks/coal_distance.py --threads 1 [--n 5000] [--repeats 3]
"""

from __future__ import annotations

import common

import gdnplan as gp
from gdnplan import distance

ENVS = ["a", "b", "c", "d", "e"]


def main() -> None:
    p = common.parser("coal_distance", __doc__)
    p.add_argument("--n", type=int, default=5000)
    p.add_argument("--repeats", type=int, default=3)
    args = common.parse(p)
    report = common.Report(args, "coal ground truth", common.first_paragraph(__doc__))
    report.text(f"{args.n} configurations per environment, best of {args.repeats} (s).")
    table = report.table(
        "env",
        "distance, 1 core (s)",
        "distance + grad, 1 core (s)",
        "distance + grad, all cores (s)",
        "µs / config (all cores)",
    )
    parallel = distance.PARALLEL_MIN_BATCH
    for env in ENVS:
        scene = gp.make_scene(env, seed=0)
        q = scene.robot.sample(args.n, seed=0)
        distance.checker(scene)  # build coal shapes outside the timing

        def on(cores_from: int, fn, s=scene, q=q):
            def call():
                distance.PARALLEL_MIN_BATCH = cores_from
                fn(s, q)

            return call

        t = common.time_calls(
            {
                "d": on(10**12, gp.signed_distance),
                "d+grad": on(10**12, gp.signed_distance_and_grad),
                "d+grad, all cores": on(parallel, gp.signed_distance_and_grad),
            },
            repeats=args.repeats,
        )
        distance.PARALLEL_MIN_BATCH = parallel
        best = [t[k].best for k in ("d", "d+grad", "d+grad, all cores")]
        table.add(env, *(f"{s:.3f}" for s in best), f"{1e6 * best[2] / args.n:.1f}")
    report.write()


if __name__ == "__main__":
    main()
