"""Training batches of ``ur5e_storage`` shards: a robot graph per sample.

A storage scene's robot is one of two variants (:mod:`gdnplan.data.samples_storage3d`): the
fingers open, or closed on the scene's stick and holding it. The two have different graphs
(the held stick adds its box's 8 nodes), and within a variant the node *structure* (count,
bodies, neighbourhoods) is the same while the node *positions* in their bodies' frames depend
on the scene (the stick's length and width, the finger opening). A batch is therefore split
by variant into at most two parts; a part's node positions and Jacobians come, row by row,
from the graph of the row's own scene robot (:func:`gdnplan.graph3d.robot_graph3d`), its
neighbourhoods from any of them (checked equal), and its obstacle input from the graphs of
its scenes (:func:`gdnplan.graph3d.scene_graph3d`: the table and walls with grid nodes),
padded (:func:`~gdnplan.models.graphdistnet3d.obstacle_input`). Rows are reordered part by
part; ``d`` and ``grad`` follow the same order.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import torch

from ..data.samples_storage3d import storage_scene_of
from ..graph3d import RobotGraph3D, robot_graph3d, scene_graph3d
from ..models.graphdistnet3d import (
    GraphDistNet3D,
    ObstacleInput,
    forward_with_grad,
    obstacle_input,
    robot_tensors,
)


@dataclass(frozen=True)
class _Part:
    graph: RobotGraph3D  # the neighbourhoods of the part's robot variant
    nodes: torch.Tensor  # (B, N_r, 3)
    jac: torch.Tensor  # (B, N_r, 3, dof)
    obstacles: ObstacleInput
    scene_rows: torch.Tensor  # (B,) row of each sample in ``obstacles``


class StorageBatch3D:
    """Model inputs of some rows of a ``ur5e_storage`` shard (float32 tensors), the interface
    of :class:`gdnplan.train.batch3d.Batch3D` (whose ``graph`` argument it ignores)."""

    def __init__(self, rim: int, shard: dict, rows: np.ndarray):
        rows = np.asarray(rows)
        variant = shard["variant"][shard["scene"][rows]]
        self.parts: list[_Part] = []
        ordered = []
        for v in np.unique(variant):
            r = rows[variant == v]
            scenes, inverse = np.unique(shard["scene"][r], return_inverse=True)
            inverse = inverse.reshape(-1)
            built = [
                storage_scene_of(shard["storage"][s], shard["placement"][s], int(v)) for s in scenes
            ]
            graphs = [robot_graph3d(sc.robot, rim) for sc in built]
            first = graphs[0]
            if any(not np.array_equal(g.nbr, first.nbr) for g in graphs):
                raise AssertionError("storage: one variant's robot graphs differ in structure")
            nodes = np.empty((len(r), first.n_nodes, 3))
            jac = np.empty((len(r), first.n_nodes, 3, first.robot.dof))
            for i, g in enumerate(graphs):
                here = inverse == i
                nodes[here], jac[here] = g.positions_and_jacobians(shard["q"][r[here]])
            self.parts.append(
                _Part(
                    first,
                    torch.as_tensor(nodes, dtype=torch.float32),
                    torch.as_tensor(jac, dtype=torch.float32),
                    obstacle_input([scene_graph3d(sc) for sc in built]),
                    torch.as_tensor(inverse, dtype=torch.long),
                )
            )
            ordered.append(r)
        self.rows = np.concatenate(ordered)
        self.d = torch.as_tensor(shard["d"][self.rows], dtype=torch.float32)
        self.grad = torch.as_tensor(shard["grad"][self.rows], dtype=torch.float32)

    def run(self, net: GraphDistNet3D, graph=None, create_graph: bool = False):
        """d̂ (B,) and ∂d̂/∂q (B, dof) in the order of ``rows``."""
        out = []
        for p in self.parts:
            feats = net.obstacle_pass(p.obstacles).take(p.scene_rows)
            out.append(forward_with_grad(net, p.graph, p.nodes, p.jac, feats, create_graph))
        return torch.cat([d for d, _ in out]), torch.cat([g for _, g in out])

    def distance(self, net: GraphDistNet3D, graph=None) -> torch.Tensor:
        """d̂ (B,) alone (no double backward)."""
        out = []
        for p in self.parts:
            feats = net.obstacle_pass(p.obstacles).take(p.scene_rows)
            nbr, nbr_mask = robot_tensors(p.graph)
            out.append(net(p.nodes, nbr, nbr_mask, feats))
        return torch.cat(out)


__all__ = ["StorageBatch3D"]
