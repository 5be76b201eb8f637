"""GraphDistNet distance + gradient under ``--threads`` torch threads (1) vs torch's default.

On scene ``env`` (seed 0) with its shipped weights, ``distance_and_grad`` of ``batch`` random
configurations (64: a planner-sized call) runs under three settings, interleaved call by call
(so a change of load hits all three alike), after a warm-up:

- ``default``: the model's ``threads`` set to torch's default count (one per core; the
  compiled whole pass of models/graphdistnet/fused_net.py then runs its tiles on that many
  threads);
- ``n threads``: torch's global count n (``--threads``, 1 by default) and the model's n (no
  switching);
- ``n threads, switched``: the caller at torch's default, the model at n (the library default):
  :func:`gdnplan.models.threads.torch_threads` sets n and restores the default on every call.

Then the whole planner, where the network calls alternate with Ipopt, CasADi and coal:
``gdnplan.plan`` of ``problems/planar7_d.toml`` with GraphDistNet, the inference threads at
torch's default and at n, interleaved, ``--plans`` times each (0: skip). Reports the median
seconds, default / n threads, and the cost of switching.

    python benchmarks/threads.py --threads 1 [--env d] [--batch 64 1000] [--rounds 30] [--plans 2]
"""

from __future__ import annotations

import common
import torch

import gdnplan as gp
from gdnplan.models import set_inference_threads

TORCH_DEFAULT = torch.get_num_threads()  # before common.parse applies --threads
WEIGHTS = common.ROOT / "weights"


def measure(env: str, batch: int, rounds: int, n: int) -> dict[str, float]:
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
        "default": call(TORCH_DEFAULT, TORCH_DEFAULT),
        "n": call(n, n),
        "n, switched": call(n, TORCH_DEFAULT),
    }
    t = common.time_calls(settings, repeats=rounds)
    torch.set_num_threads(n)
    return {name: timing.median for name, timing in t.items()}


def measure_plans(rounds: int, n: int) -> dict[str, float]:
    """Median seconds of ``gdnplan.plan`` (planar7_d, GraphDistNet) per inference thread count."""
    problem = gp.Problem.from_toml(common.ROOT / "problems" / "planar7_d.toml")

    def plan(threads: int):
        def run() -> None:
            set_inference_threads(threads)
            gp.plan(problem, collision="graphdistnet")

        return run

    t = common.time_calls({"default": plan(TORCH_DEFAULT), "n": plan(n)}, repeats=rounds)
    set_inference_threads(n)
    return {name: timing.median for name, timing in t.items()}


def main() -> None:
    p = common.parser("threads", __doc__)
    p.add_argument("--env", default="d")
    p.add_argument("--batch", type=int, nargs="+", default=[64, 1000])
    p.add_argument("--rounds", type=int, default=30)
    p.add_argument("--plans", type=int, default=2, help="plans per setting (0: none)")
    args = common.parse(p)
    n = args.threads
    report = common.Report(args, "Inference threads", common.first_paragraph(__doc__))
    report.text(
        f"torch default threads: {TORCH_DEFAULT}; env {args.env}; {args.rounds} rounds "
        f"(median s); {args.plans} plans per setting."
    )
    table = report.table(
        "batch",
        f"default ({TORCH_DEFAULT} threads) (s)",
        f"{n} thread(s) (s)",
        f"{n} thread(s), switched (s)",
        f"default / {n} thread(s)",
        f"switched / {n} thread(s)",
    )
    for batch in args.batch:
        t = measure(args.env, batch, args.rounds, n)
        table.add(
            batch,
            f"{t['default']:.4f}",
            f"{t['n']:.4f}",
            f"{t['n, switched']:.4f}",
            f"{t['default'] / t['n']:.2f}×",
            f"{t['n, switched'] / t['n']:.2f}×",
        )
    if args.plans:
        t = measure_plans(args.plans, n)
        table.add(
            "plan planar7_d",
            f"{t['default']:.2f}",
            f"{t['n']:.2f}",
            "(the library default)",
            f"{t['default'] / t['n']:.2f}×",
            "",
        )
    report.write()


if __name__ == "__main__":
    main()
