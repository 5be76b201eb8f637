"""GraphDistNet's inputs for a whole dataset (:class:`Tensors`), built once, and its batched
predictions with ∂d̂/∂q = Σ_n (∂d̂/∂p_n) ∂p_n/∂q through the node Jacobians."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import torch

from ..data import Dataset, env_robot
from ..graph import GraphBatch, RobotGraph, obstacle_graph, robot_graph, variant_graphs
from ..models.graphdistnet import GraphDistNet, GraphDistNetConfig


@dataclass(frozen=True)
class Tensors:
    """A dataset as model-ready tensors (float32), built once.

    Attributes:
        q: (n, dof) float64 numpy joint angles.
        nodes: (n, N_r, 2) robot node positions.
        jac: (n, N_r, 2, dof) node Jacobians (float32).
        obstacles: obstacle graphs of all samples.
        d: (n,) coal signed distances.
        grad: (n, dof) coal ∂f/∂q.
        robot: per-sample robot graph structure (``ur5e``: the robot varies per sample),
            padded to N_r nodes; None when every sample has ``graph``'s structure.
    """

    graph: RobotGraph
    q: np.ndarray
    nodes: torch.Tensor
    jac: torch.Tensor
    obstacles: GraphBatch
    d: torch.Tensor
    grad: torch.Tensor
    robot: GraphBatch | None = None

    def __len__(self) -> int:
        return len(self.q)

    def batch(self, rows: torch.Tensor, device: str) -> tuple[GraphBatch, GraphBatch]:
        if self.robot is None:
            robot = self.graph.batch(self.nodes[rows], device=device)
        else:
            r = self.robot  # not trimmed: rows keep N_r nodes, like the Jacobians
            robot = GraphBatch(r.nodes[rows], r.prev[rows], r.next[rows], r.mask[rows]).to(device)
        return robot, self.obstacles.index(rows).to(device)


def tensors(ds: Dataset, config: GraphDistNetConfig | None = None) -> Tensors:
    """Robot nodes, Jacobians and obstacle graphs of a dataset (``config`` is not needed: the
    graphs are the polygons' own for every architecture; it is accepted for older callers).

    Samples with different robots (``ds.variants()``) get their own graph structures, padded
    to the largest (Jacobians of padded nodes are zero); ``graph`` is then the environment
    robot's graph (its reach is the metrics' unit).
    """
    graph = robot_graph(env_robot(ds.env))
    if ds.gripper is None:
        nodes, jac = graph.positions_and_jacobians(ds.q)
        structure = None
    else:
        groups = [(ds.robot(int(rows[0])), rows) for rows in ds.variants().values()]
        nodes, jac, structure = variant_graphs(groups, ds.q)
    return Tensors(
        graph,
        ds.q,
        torch.as_tensor(nodes, dtype=torch.float32),
        torch.as_tensor(jac, dtype=torch.float32),
        obstacle_graph(ds.obstacles, ds.sizes),
        torch.as_tensor(ds.d, dtype=torch.float32),
        torch.as_tensor(ds.grad, dtype=torch.float32),
        structure,
    )


def forward_with_grad(
    net: GraphDistNet,
    robot: GraphBatch,
    obstacles: GraphBatch,
    jac: torch.Tensor,
    create_graph: bool,
    generator: torch.Generator | None = None,
) -> tuple[torch.Tensor, torch.Tensor]:
    """d̂ (B,) and ∂d̂/∂q (B, dof) = Σ_n ∂d̂/∂p_n · J_n with J (B, N_r, 2, dof)."""
    x = robot.nodes.detach().requires_grad_(True)
    with torch.enable_grad():
        d = net(robot.with_nodes(x), obstacles, generator)
        (dx,) = torch.autograd.grad(d.sum(), x, create_graph=create_graph)
    return d, torch.einsum("bni,bnij->bj", dx, jac)


def predict(
    net: GraphDistNet,
    t: Tensors,
    chunk: int = 256,
    device: str = "cpu",
    grad: bool = True,
    seed: int = 0,
) -> tuple[np.ndarray, np.ndarray | None]:
    """d̂ (n,) and, with ``grad``, ∂d̂/∂q (n, dof) for every sample of ``t`` (float64);
    ``seed`` seeds the generator of the paper network's random first-layer partners (one
    stream over the chunks of ``chunk`` samples)."""
    net.eval()
    gen = torch.Generator(device=device).manual_seed(seed)
    ds, gs = [], []
    for s in range(0, len(t), chunk):
        rows = torch.arange(s, min(s + chunk, len(t)))
        robot, obstacles = t.batch(rows, device)
        if grad:
            d, g = forward_with_grad(net, robot, obstacles, t.jac[rows].to(device), False, gen)
            gs.append(g.detach().double().cpu().numpy())
        else:
            with torch.inference_mode():
                d = net(robot, obstacles, gen)
        ds.append(d.detach().double().cpu().numpy())
    return np.concatenate(ds), (np.concatenate(gs) if grad else None)
