"""signed_ring_distance against its textbook form, side by side in one run.

Points: the robot graph's nodes at n random configurations of each scene (seed 3), each node
repeated 5 times (as many points as nodes plus the probes of ``probe_split=5``); obstacles: the
scene's rings. Both forms compute s (B, P) and ∂s/∂points by autograd, in chunks of ``chunk``
configurations (``--threads`` torch threads). The textbook form differentiates through all
point-edge pairs ((B, P, M, 2) tensors);
:func:`gdnplan.models.graphdistnet.signed_ring_distance` finds the nearest edge and the winding
number without autograd on separate x/y tensors and differentiates the nearest edge only.
Reports the best time of each (interleaved repeats after one warm-up), their ratio and the
largest differences.

    python benchmarks/ring_distance.py --threads 1 [--envs c d e] [--n 1000] [--chunk 100]
"""

from __future__ import annotations

import common
import numpy as np
import torch

import gdnplan as gp
from gdnplan.graph import obstacle_graph, robot_graph, scene_obstacles
from gdnplan.models.graphdistnet import PAD_DIST2, signed_ring_distance


def textbook(
    points: torch.Tensor, nodes: torch.Tensor, next: torch.Tensor, mask: torch.Tensor
) -> torch.Tensor:
    """± min_m |p − a_m − t e_m| with autograd through every pair (the docstring's formula)."""
    ends = torch.gather(nodes, 1, next[..., None].expand(*next.shape, 2))
    e = (ends - nodes)[:, None]
    w = points[:, :, None] - nodes[:, None]
    t = ((w * e).sum(-1) / (e * e).sum(-1).clamp_min(1e-12)).clamp(0.0, 1.0)
    d2 = ((w - t[..., None] * e) ** 2).sum(-1).masked_fill(~mask[:, None], PAD_DIST2)
    dist = d2.amin(-1).clamp_min(1e-12).sqrt()
    with torch.no_grad():
        wy, ey = w[..., 1], e[..., 1]
        left = e[..., 0] * wy - ey * w[..., 0]
        up = (wy >= 0) & (wy < ey)
        down = (wy < 0) & (wy >= ey)
        winding = ((up & (left > 0)).int() - (down & (left < 0)).int()).masked_fill(
            ~mask[:, None], 0
        )
    return torch.where(winding.sum(-1) != 0, -dist, dist)


def run(fn, points: torch.Tensor, graph, chunk: int) -> tuple[torch.Tensor, torch.Tensor]:
    """s and ∂(Σ s)/∂points of ``fn`` over all points, to the rings of ``graph``, by chunks."""
    values, grads = [], []
    for start in range(0, len(points), chunk):
        p = points[start : start + chunk].clone().requires_grad_(True)
        s = fn(p, graph.nodes, graph.next, graph.mask)
        s.sum().backward()
        values.append(s.detach())
        grads.append(p.grad)
    return torch.cat(values), torch.cat(grads)


def main() -> None:
    p = common.parser("ring_distance", __doc__)
    p.add_argument("--envs", nargs="+", default=["c", "d", "e"])
    p.add_argument("--n", type=int, default=1000)
    p.add_argument("--chunk", type=int, default=100)
    p.add_argument("--repeats", type=int, default=5)
    args = common.parse(p)
    report = common.Report(
        args, "signed_ring_distance against its textbook form", common.first_paragraph(__doc__)
    )
    report.text(
        f"n = {args.n} configurations, chunks of {args.chunk}, best of {args.repeats}; forward "
        "+ ∂s/∂points."
    )
    table = report.table(
        "env", "points × edges", "textbook (ms)", "gdnplan (ms)", "ratio", "max |Δs|, |Δ∂s|"
    )
    for env in args.envs:
        scene = gp.make_scene(env, seed=3)
        graph = obstacle_graph(*scene_obstacles([scene]))
        nodes = robot_graph(scene.robot).positions(scene.robot.sample(args.n, seed=3))
        points = torch.tensor(np.repeat(nodes, 5, axis=1), dtype=torch.float32)
        forms = {"textbook": textbook, "gdnplan": signed_ring_distance}
        out = {}

        def call(name, fn, out=out, points=points, graph=graph):
            def go():
                out[name] = run(fn, points, graph, args.chunk)

            return go

        t = common.time_calls({n: call(n, f) for n, f in forms.items()}, repeats=args.repeats)
        ds = (out["gdnplan"][0] - out["textbook"][0]).abs().max().item()
        dg = (out["gdnplan"][1] - out["textbook"][1]).abs().max().item()
        best = {name: timing.best for name, timing in t.items()}
        table.add(
            env,
            f"{points.shape[1]} × {graph.nodes.shape[1]}",
            f"{best['textbook'] * 1e3:.0f}",
            f"{best['gdnplan'] * 1e3:.0f}",
            f"{best['textbook'] / best['gdnplan']:.1f}×",
            f"{ds:.0e}, {dg:.0e}",
        )
    report.write()


if __name__ == "__main__":
    main()
