"""GraphDistNet-3D can learn: its untrained output depends on q (the previous normalisation and
PyTorch's default initialisation gave a near-constant d̂ whose gradients hardly reached the
message layers, docs/decisions.md 2026-12-02), and it overfits a few coal-labelled samples."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from gdnplan.arm3d import load_robot3d, random_boxes
from gdnplan.data.samples3d import make_shard3d
from gdnplan.graph3d import robot_graph3d
from gdnplan.models.graphdistnet3d import GraphDistNet3D, GraphDistNet3DConfig, GraphDistNet3DModel
from gdnplan.train.graphdistnet3d import Batch3D
from gdnplan.train.loss import GraphDistNetLoss, distance_loss


def test_untrained_distance_depends_on_the_configuration():
    robot = load_robot3d("ur5e")
    scene = random_boxes(robot, 20, seed=3)
    q = robot.random_configurations(32, np.random.default_rng(0))
    for seed in range(3):
        torch.manual_seed(seed)
        net = GraphDistNet3D(GraphDistNet3DConfig(scale=1.19))
        d = GraphDistNet3DModel(net, self_collision=False).learned_distance(scene, q)
        # the labels spread ≈ 0.1 m over such configurations; the old network 0.04–0.12 mm
        assert np.std(d) > 0.01


@pytest.mark.slow
def test_overfits_one_scene_of_coal_labels():
    shard = make_shard3d("ur5e_boxes", 0, 0, 50, near=0.3)
    cfg = GraphDistNet3DConfig(scale=1.19)
    graph = robot_graph3d(load_robot3d("ur5e"), cfg.rim)
    batch = Batch3D(graph, shard, np.arange(50))
    torch.manual_seed(0)
    net = GraphDistNet3D(cfg)
    opt = torch.optim.Adam(net.parameters(), lr=1e-3)
    loss_cfg = GraphDistNetLoss()
    for _ in range(150):
        loss = distance_loss(batch.distance(net, graph), batch.d, loss_cfg, cfg.scale)
        opt.zero_grad()
        loss.backward()
        opt.step()
    with torch.no_grad():
        mae = float((batch.distance(net, graph) - batch.d).abs().mean())
    constant = float((batch.d - batch.d.median()).abs().mean())
    assert mae < 0.3 * constant
