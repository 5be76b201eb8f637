"""GraphDistNet (torch reference and fused kernels) vs coal: seconds for a batch of
configurations, measured side by side in one run.

For each scene with weights (``<weights>/<env>.safetensors``, the shipped ones by default; the
UR5e ``fetch`` scene uses ``ur5e.safetensors``), on one scene (seed 0) and the same n uniformly
random configurations: coal distance and distance + exact gradient (bounding-circle broad
phase, batches split over all cores by processes) and GraphDistNet distance and distance +
∂d̂/∂q (float32, ``--threads`` torch threads) by the torch reference path (``fused=False``)
and by the fused kernels (``fused=True``: the whole-network pass of
models/graphdistnet/fused_net.py for the networks it serves, all but two-way ones with node
distances, else the ring-message kernels of models/graphdistnet/fused.py), best of the
repeats after one warm-up call each, all six interleaved round by round. An ``--envs`` entry
``env=WEIGHTS`` runs other weights on the scene (``d=results/ablation/d/soft-min-s0.safetensors``).

FLOPs: the matmul FLOPs torch runs (FlopCounterMode) plus the fused kernels' products (2 R H²
per hidden layer of the edge MLP on R edge rows, forward and backward; 2 n C H for the sparse
cross mix; :func:`network_flops` for the whole-network pass), counted by wrapping them.
The last column puts both on one core: coal's distance + gradient of the same batch in this
process (no forked workers), thread CPU s, against the fused pass's thread CPU s.
Reported: GFLOP/s of the fused kernels alone
(their FLOPs over their thread CPU seconds) and of the whole fused distance + gradient pass
(all its FLOPs over its best thread CPU seconds), each as a share of a 2048² float32 matmul
on this thread (thread CPU seconds too: the machine is shared, CPU time is what a busy core
still measures fairly).

    python benchmarks/inference.py --threads 1 [--n 5000] [--repeats 5] [--envs a b c d e fetch]
        [--envs d d=results/ablation/d/soft-min-s0.safetensors …]
"""

from __future__ import annotations

import time
from collections.abc import Callable

import common
import torch
from torch.utils.flop_counter import FlopCounterMode

import gdnplan as gp
from gdnplan import distance
from gdnplan.assets import default_weights
from gdnplan.models.graphdistnet import fused, fused_net


def network_flops(x, net, cand, d_out, g_out, tile) -> int:
    """Product FLOPs of one whole-network call (fused_net) on n rows per configuration (robot
    nodes, plus obstacle nodes for two-way networks): per configuration and layer the edge MLP
    2·3n·L·H², the last linear layer 2·n·H², the first 2·n·2·2H (coordinates) + 2·n·H·2H
    (features, layers ≥ 1), the cross mix 2·n·C·H and the readout 4·n·H, plus the head
    (P = H or 2H pooled features); the backward (when g_out has rows) the same again."""
    b, n = x.shape[0], net.ring.shape[1]
    k, h = net.att.shape
    layer = 6 * n * net.wht.shape[1] * h * h + 2 * n * h * h + 8 * n * h + 2 * n * cand * h
    layer += 4 * n * h
    head = 2 * (net.h0t.size + net.hw.size + len(net.wlast))
    forward = k * layer + (k - 1) * 4 * n * h * h + head
    return b * forward * (2 if g_out.shape[0] else 1)


KERNELS = {  # the compiled functions (module, name): FLOPs of one call from its arguments
    (fused, "_forward"): lambda u, c, ring, wt, *_: 2 * u.shape[0] * 3 * u.shape[1] * wt.size,
    (fused, "_backward"): lambda g, ring, w, *_: 2 * g.shape[0] * 3 * g.shape[1] * w.size,
    (fused, "_mix_forward"): lambda w, idx, v, out: 2 * w.size * v.shape[1],
    (fused, "_mix_backward"): lambda g, idx, v, dw: 2 * idx.size * v.shape[1],
    (fused_net._kernels, "network"): network_flops,
}


def cpu_seconds(call: Callable[[], object], repeats: int) -> float:
    """Best thread CPU seconds of ``call`` after one warm-up call."""
    call()
    best = float("inf")
    for _ in range(repeats):
        start = time.thread_time()
        call()
        best = min(best, time.thread_time() - start)
    return best


def matmul_gflops(size: int = 2048, repeats: int = 5) -> float:
    """GFLOP/s of a float32 (size × size) matmul on this thread: the practical peak."""
    a, b = torch.randn(size, size), torch.randn(size, size)
    return 2 * size**3 / cpu_seconds(lambda: a @ b, repeats) / 1e9


def metered(call: Callable[[], object]) -> tuple[int, int, float]:
    """(torch matmul FLOPs, kernel FLOPs, kernel thread CPU seconds) of one ``call``."""
    originals = {key: getattr(*key) for key in KERNELS}
    kernel = {"flops": 0, "seconds": 0.0}

    def wrap(key: tuple):
        def run(*args):
            start = time.thread_time()
            originals[key](*args)
            kernel["seconds"] += time.thread_time() - start
            kernel["flops"] += KERNELS[key](*args)

        return run

    try:
        for key in KERNELS:
            setattr(*key, wrap(key))
        with FlopCounterMode(display=False) as counter:
            call()
    finally:
        for (module, name), original in originals.items():
            setattr(module, name, original)
    return counter.get_total_flops(), kernel["flops"], kernel["seconds"]


def coal_one_core(scene, q) -> None:
    """Coal's distance and exact gradient of the batch in this process (no forked workers)."""
    w = distance.checker(scene).closest(q, per_link=False)
    distance.witness_gradient(scene, q, w)


def row(
    table: common.Table, env: str, n: int, repeats: int, peak: float, name: str | None = None
) -> None:
    """One table row: seconds of coal and both GraphDistNet paths for n configurations, with
    the weights ``name`` (a name or a file; None: the scene's shipped default)."""
    scene = gp.make_scene(env, seed=0)
    q = scene.robot.sample(n, seed=0)
    name = name or default_weights(scene)
    reference, fast = (gp.load_model(name) for _ in range(2))
    reference.fused, fast.fused = False, True
    distance.checker(scene)
    calls = {
        "coal d": lambda: gp.signed_distance(scene, q),
        "coal d+grad": lambda: gp.signed_distance_and_grad(scene, q),
        "ref d": lambda: reference.distance(scene, q),
        "ref d+grad": lambda: reference.distance_and_grad(scene, q),
        "fused d": lambda: fast.distance(scene, q),
        "fused d+grad": lambda: fast.distance_and_grad(scene, q),
    }
    t = {key: timing.best for key, timing in common.time_calls(calls, repeats).items()}
    torch_flops, kernel_flops, kernel_seconds = metered(calls["fused d+grad"])
    pass_cpu = cpu_seconds(calls["fused d+grad"], repeats)
    coal_cpu = cpu_seconds(lambda: coal_one_core(scene, q), repeats)
    kernel_gflops = kernel_flops / kernel_seconds / 1e9
    pass_gflops = (torch_flops + kernel_flops) / pass_cpu / 1e9
    table.add(
        f"{env} ({scene.robot.name}, {name})",
        *(f"{t[key]:.3f}" for key in calls),
        f"{t['fused d'] / t['coal d']:.2f}×",
        f"{t['fused d+grad'] / t['coal d+grad']:.2f}×",
        f"{t['fused d+grad'] / t['ref d+grad']:.2f}×",
        f"{kernel_gflops:.1f} ({100 * kernel_gflops / peak:.0f} %)",
        f"{pass_gflops:.1f} ({100 * pass_gflops / peak:.0f} %), {pass_cpu:.3f} s",
        f"{coal_cpu:.3f} s, {pass_cpu / coal_cpu:.2f}×",
    )


def main() -> None:
    p = common.parser("inference", __doc__)
    p.add_argument("--n", type=int, default=5000)
    p.add_argument("--repeats", type=int, default=5)
    p.add_argument("--envs", nargs="+", default=["a", "b", "c", "d", "e", "fetch"])
    args = common.parse(p)
    report = common.Report(args, "Inference: GraphDistNet vs coal", common.first_paragraph(__doc__))
    peak = matmul_gflops()
    report.text(
        f"n = {args.n} configurations, best of {args.repeats} (wall s); weights: the shipped "
        f"default of each scene (gdnplan.assets.default_weights); coal over all cores (forked "
        f"workers), GraphDistNet on {args.threads} torch thread(s); float32 matmul peak on "
        f"this thread: {peak:.1f} GFLOP/s (thread CPU time)."
    )
    table = report.table(
        "env (robot, weights)",
        "coal d (s)",
        "coal d+grad (s)",
        "ref d (s)",
        "ref d+grad (s)",
        "fused d (s)",
        "fused d+grad (s)",
        "fused/coal d",
        "fused/coal d+grad",
        "fused/ref d+grad",
        "fused kernels GFLOP/s (share of peak)",
        "fused d+grad pass GFLOP/s (share), CPU s",
        "coal d+grad on one core, CPU s; fused pass / it",
    )
    for entry in args.envs:  # env, or env=weights
        env, _, name = entry.partition("=")
        row(table, env, args.n, args.repeats, peak, name or None)
    report.write()


if __name__ == "__main__":
    main()
