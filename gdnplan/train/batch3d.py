"""GraphDistNet-3D's inputs of some rows of a 3-D shard, and d̂ with ∂d̂/∂q on them.

A batch's robot nodes and node Jacobians come from Pinocchio
(:meth:`~gdnplan.graph3d.RobotGraph3D.positions_and_jacobians`); the obstacle features are
computed once per scene of the batch (one-way cross edges) and handed to its rows. A
``ur5e_storage`` shard's rows have a robot graph each (fingers open or holding the stick:
:mod:`gdnplan.train.batch_storage3d`); :func:`make_batch` picks the kind.
"""

from __future__ import annotations

import numpy as np
import torch

from ..graph3d import point_cloud_graph
from ..models.graphdistnet3d import (
    GraphDistNet3D,
    boxes_input,
    forward_with_grad,
    obstacle_input,
    robot_tensors,
)
from .batch_storage3d import StorageBatch3D

CLOUD_K = 6  # neighbours of a point in a cloud's graph


class Batch3D:
    """Model inputs of some rows of a shard (float32 tensors)."""

    def __init__(self, graph, shard: dict, rows: np.ndarray):
        q = shard["q"][rows]
        nodes, jac = graph.positions_and_jacobians(q)
        scenes, inverse = np.unique(shard["scene"][rows], return_inverse=True)
        self.nodes = torch.as_tensor(nodes, dtype=torch.float32)
        self.jac = torch.as_tensor(jac, dtype=torch.float32)
        if "points" in shard:  # ur5e_cloud: the kNN graph of every scene's cloud
            graphs = [point_cloud_graph(shard["points"][s], CLOUD_K) for s in scenes]
            self.obstacles = obstacle_input(graphs)
        else:
            self.obstacles = boxes_input(shard["box_center"][scenes], shard["box_size"][scenes])
        self.scene_rows = torch.as_tensor(inverse.reshape(-1), dtype=torch.long)
        self.d = torch.as_tensor(shard["d"][rows], dtype=torch.float32)
        self.grad = torch.as_tensor(shard["grad"][rows], dtype=torch.float32)

    def run(self, net: GraphDistNet3D, graph, create_graph: bool):
        """d̂ (B,) and ∂d̂/∂q (B, dof); ``create_graph`` to train on the gradient."""
        feats = net.obstacle_pass(self.obstacles).take(self.scene_rows)
        return forward_with_grad(net, graph, self.nodes, self.jac, feats, create_graph)

    def distance(self, net: GraphDistNet3D, graph) -> torch.Tensor:
        """d̂ (B,) alone (training on the distance loss only: no double backward)."""
        feats = net.obstacle_pass(self.obstacles).take(self.scene_rows)
        nbr, nbr_mask = robot_tensors(graph)
        return net(self.nodes, nbr, nbr_mask, feats)


def make_batch(graph, shard: dict, rows: np.ndarray, rim: int):
    """The batch of some rows of a shard: :class:`Batch3D` with the robot ``graph``, or for a
    ``ur5e_storage`` shard (robot variants) a :class:`StorageBatch3D` (a robot graph per row)."""
    if "variant" in shard:
        return StorageBatch3D(rim, shard, rows)
    return Batch3D(graph, shard, rows)


__all__ = ["CLOUD_K", "Batch3D", "make_batch"]
