"""signed_ring_distance against its textbook form, side by side in one run.

Usage: python benchmarks/ring_distance.py [--envs c d e] [--n 1000] [--chunk 100] [--repeats 5]

Points: the robot graph's nodes at n random configurations of each scene (seed 3), each node
repeated 5 times (as many points as nodes plus the probes of ``probe_split=5``); obstacles: the
scene's rings. Both forms compute s (B, P) and ∂s/∂points by autograd, in chunks of ``chunk``
configurations on one torch thread. The textbook form differentiates through all point-edge pairs
((B, P, M, 2) tensors); :func:`gdnplan.models.graphdistnet.signed_ring_distance` finds the
nearest edge and the winding number without autograd on separate x/y tensors and differentiates
the nearest edge only. Prints the best time of each, their ratio and the largest differences.
"""

from __future__ import annotations

import argparse
import time

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
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--envs", nargs="+", default=["c", "d", "e"])
    parser.add_argument("--n", type=int, default=1000)
    parser.add_argument("--chunk", type=int, default=100)
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    torch.set_num_threads(1)
    print(f"{time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}, n={args.n}, chunk={args.chunk}")
    for env in args.envs:
        scene = gp.make_scene(env, seed=3)
        graph = obstacle_graph(*scene_obstacles([scene]))
        nodes = robot_graph(scene.robot).positions(scene.robot.sample(args.n, seed=3))
        points = torch.tensor(np.repeat(nodes, 5, axis=1), dtype=torch.float32)
        forms = {"textbook": textbook, "gdnplan": signed_ring_distance}
        best, out = dict.fromkeys(forms, np.inf), {}
        for _ in range(args.repeats):
            for name, fn in forms.items():
                start = time.perf_counter()
                out[name] = run(fn, points, graph, args.chunk)
                best[name] = min(best[name], time.perf_counter() - start)
        ds = (out["gdnplan"][0] - out["textbook"][0]).abs().max().item()
        dg = (out["gdnplan"][1] - out["textbook"][1]).abs().max().item()
        print(
            f"{env}: {points.shape[1]} points x {graph.nodes.shape[1]} edges, "
            f"textbook {best['textbook'] * 1e3:.0f} ms, gdnplan {best['gdnplan'] * 1e3:.0f} ms, "
            f"ratio {best['textbook'] / best['gdnplan']:.2f}x; max |Δs| {ds:.1e}, |Δ∂s| {dg:.1e}"
        )


if __name__ == "__main__":
    main()
