"""Obstacle graphs of large boxes: grid nodes over faces wider than the training boxes."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import torch

from gdnplan.arm3d import box_obstacle, load_robot3d, random_boxes
from gdnplan.arm3d.storage3d import table_obstacle
from gdnplan.graph3d import (
    FACE_SPACING,
    box_graphs,
    box_grid,
    obstacle_graph3d,
    robot_graph3d,
    scene_graph3d,
)

WEIGHTS = Path(__file__).parents[1] / "weights" / "ur5e_boxes3d_preliminary.safetensors"


def _face_samples(half: np.ndarray, n: int, rng) -> np.ndarray:
    """n points uniform on the faces of a box of half sides ``half`` (its own frame)."""
    u = rng.uniform(-1, 1, (n, 3))
    axis = rng.integers(0, 3, n)
    u[np.arange(n), axis] = rng.choice([-1.0, 1.0], n)
    return u * half


@pytest.mark.parametrize("sides", [(0.95, 1.6, 0.05), (0.5, 0.02, 0.4), (0.21, 0.1, 0.1)])
def test_large_box_nodes_cover_every_face(sides):
    half = np.asarray(sides) / 2
    pts, edges = box_grid(half)
    # every node on the surface, every corner a node
    on = np.isclose(np.abs(pts), half).any(axis=1)
    assert on.all()
    corners = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]) * half
    assert all(np.isclose(pts, c).all(axis=1).any() for c in corners)
    # a face point is within half a grid cell diagonal of a node
    samples = _face_samples(half, 4000, np.random.default_rng(0))
    gap = np.linalg.norm(samples[:, None] - pts[None], axis=2).min(axis=1).max()
    assert gap <= FACE_SPACING * np.sqrt(2) / 2 + 1e-9
    # edges join lattice neighbours: one axis, one step ≤ FACE_SPACING
    step = np.abs(pts[edges[:, 0]] - pts[edges[:, 1]])
    assert ((step > 1e-12).sum(axis=1) == 1).all() and step.max() <= FACE_SPACING + 1e-9
    assert len(np.unique(np.sort(edges, axis=1), axis=0)) == len(edges)


def test_the_table_graph_has_grid_nodes_and_small_boxes_keep_their_corners():
    table = obstacle_graph3d(table_obstacle())
    assert table.n_nodes > 8
    small = box_obstacle((0.2, 0.05, 0.2), (0.5, 0.1, 0.3))
    g = obstacle_graph3d(small)
    ref = box_graphs(np.array([[0.5, 0.1, 0.3]]), np.array([[0.2, 0.05, 0.2]]))
    assert np.array_equal(g.nodes, ref.nodes)
    assert np.array_equal(g.nbr, ref.nbr) and np.array_equal(g.nbr_mask, ref.nbr_mask)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_shipped_weights_give_the_training_path_distance_on_boxes_scenes(seed):
    """d̂ of the model (scene graphs) equals d̂ through the trainer's box_graphs input."""
    from gdnplan.models.graphdistnet3d import (
        boxes_input,
        load_graphdistnet3d,
        robot_tensors,
    )

    model = load_graphdistnet3d(WEIGHTS, threads=1, fused=False)
    robot = load_robot3d("ur5e")
    scene = random_boxes(robot, 20, seed=seed)
    g = scene_graph3d(scene)
    centres = np.array([o.pose.getTranslation() for o in scene.obstacles])
    sizes = np.array([2 * np.asarray(o.shape.halfSide) for o in scene.obstacles])
    ref = box_graphs(centres, sizes)
    assert np.array_equal(g.nodes, ref.nodes) and np.array_equal(g.nbr, ref.nbr)
    q = robot.random_configurations(64, np.random.default_rng(seed))
    d_model = model.learned_distance(scene, q)
    net = model.net
    graph = robot_graph3d(robot, net.config.rim)
    with torch.no_grad():
        feats = net.obstacle_pass(boxes_input(centres[None], sizes[None]))
        feats = feats.take(torch.zeros(len(q), dtype=torch.long))
        nbr, mask = robot_tensors(graph)
        nodes = torch.as_tensor(graph.positions(q), dtype=torch.float32)
        d_train = net(nodes, nbr, mask, feats).double().numpy()
    np.testing.assert_allclose(d_model, d_train, atol=1e-6)
