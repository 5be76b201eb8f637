"""GraphDistNet vs coal: seconds for a batch of configurations, measured side by side in one run.

For each scene with weights (``<weights>/<env>.safetensors``, the shipped ones by default; the
UR5e ``fetch`` scene uses ``ur5e.safetensors``), on one scene (seed 0) and the same n uniformly
random configurations: coal distance and distance + exact gradient (bounding-circle broad
phase, batches split over all cores by processes) and GraphDistNet distance and distance +
∂d̂/∂q (float32, ``--threads`` torch threads), best of the repeats after one warm-up call each.
Also the achieved GFLOP/s of the GraphDistNet distance pass (matmul FLOPs counted by torch's
FlopCounterMode) against the GFLOP/s of a 2048² float32 matmul with the same threads.

    python benchmarks/inference.py --threads 1 [--n 5000] [--repeats 3] [--envs a b c d e fetch]
    python benchmarks/inference.py --threads 2 --envs d e \
        --out benchmarks/results/inference_2threads.md
"""

from __future__ import annotations

import common
import torch
from torch.utils.flop_counter import FlopCounterMode

import gdnplan as gp
from gdnplan import distance
from gdnplan.assets import default_weights


def matmul_gflops(size: int = 2048, repeats: int = 5) -> float:
    """GFLOP/s of a float32 (size × size) matmul: the practical peak of this CPU."""
    a, b = torch.randn(size, size), torch.randn(size, size)
    seconds = common.time_calls({"mm": lambda: a @ b}, repeats=repeats)["mm"].best
    return 2 * size**3 / seconds / 1e9


def forward_flops(model, scene: gp.Scene, q) -> int:
    """Matmul FLOPs of ``model.distance(scene, q)``."""
    with FlopCounterMode(display=False) as counter:
        model.distance(scene, q)
    return counter.get_total_flops()


def row(table: common.Table, env: str, n: int, repeats: int, peak: float) -> None:
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
    t = {name: timing.best for name, timing in common.time_calls(calls, repeats).items()}
    gflops = forward_flops(model, scene, q) / t["GDN d"] / 1e9
    table.add(
        f"{env} ({scene.robot.name})",
        *(f"{s:.3f}" for s in t.values()),
        f"{t['GDN d'] / t['coal d']:.1f}×",
        f"{t['GDN d+grad'] / t['coal d+grad']:.1f}×",
        f"{gflops:.1f} ({100 * gflops / peak:.0f} %)",
    )


def main() -> None:
    p = common.parser("inference", __doc__)
    p.add_argument("--n", type=int, default=5000)
    p.add_argument("--repeats", type=int, default=3)
    p.add_argument("--envs", nargs="+", default=["a", "b", "c", "d", "e", "fetch"])
    args = common.parse(p)
    report = common.Report(args, "Inference: GraphDistNet vs coal", common.first_paragraph(__doc__))
    peak = matmul_gflops()
    report.text(
        f"n = {args.n} configurations, best of {args.repeats}; weights: the shipped default of "
        f"each scene (gdnplan.assets.default_weights); coal over all cores (forked workers), "
        f"GraphDistNet on {args.threads} torch thread(s); float32 matmul peak "
        f"({args.threads} threads): {peak:.1f} GFLOP/s."
    )
    table = report.table(
        "env (robot)",
        "coal d (s)",
        "coal d+grad (s)",
        "GDN d (s)",
        "GDN d+grad (s)",
        "GDN/coal d",
        "GDN/coal d+grad",
        "GDN d GFLOP/s (share of peak)",
    )
    for env in args.envs:
        row(table, env, args.n, args.repeats, peak)
    report.write()


if __name__ == "__main__":
    main()
