"""Robot and obstacle ring graphs: structure, densification, Jacobians, collation, bad input."""

import numpy as np
import pytest
import torch

import gdnplan as gp
from gdnplan.geometry import densify, square
from gdnplan.graph import (
    GraphBatch,
    collate,
    obstacle_graph,
    rings,
    robot_graph,
    scene_obstacles,
)


def ring_cycles(prev: np.ndarray, next: np.ndarray, mask: np.ndarray) -> list[int]:
    """Lengths of the cycles traced by ``next`` over the real nodes (checks prev ∘ next = id)."""
    idx = np.flatnonzero(mask)
    assert np.all(prev[next[idx]] == idx)
    seen, lengths = set(), []
    for start in idx:
        if start in seen:
            continue
        n, i = 0, start
        while True:
            seen.add(i)
            n += 1
            i = next[i]
            if i == start:
                break
        lengths.append(n)
    return sorted(lengths)


def test_rings_compact_padded_polygons():
    tri = np.array([[0, 0], [1, 0], [0, 1]], float)
    sq = square((3, 3), 1.0)
    polys = np.zeros((2, 2, 4, 2))
    polys[0, 0, :3], polys[0, 1] = tri, sq
    polys[1, 1, :3] = tri  # slot 0 empty
    sizes = np.array([[3, 4], [0, 3]])
    g = obstacle_graph(polys, sizes)
    assert g.nodes.shape == (2, 7, 2)
    assert g.mask.sum(1).tolist() == [7, 3]
    np.testing.assert_allclose(g.nodes[0, :3].numpy(), tri)
    np.testing.assert_allclose(g.nodes[1, :3].numpy(), tri)
    for b, expected in ((0, [3, 4]), (1, [3])):
        cyc = ring_cycles(g.prev[b].numpy(), g.next[b].numpy(), g.mask[b].numpy())
        assert cyc == expected
    # padded slots point to themselves
    assert torch.equal(g.prev[1, 3:], torch.arange(3, 7))


def test_obstacle_densify_matches_geometry_densify():
    scene = gp.make_scene("e", seed=4)
    polys, sizes = scene_obstacles([scene])
    g = obstacle_graph(polys, sizes, max_edge=0.05, dtype=torch.float64)
    expected = np.concatenate([densify(p, 0.05) for p in scene.obstacles])
    np.testing.assert_allclose(g.nodes[0, g.mask[0]].numpy(), expected, atol=1e-12)
    cyc = ring_cycles(g.prev[0].numpy(), g.next[0].numpy(), g.mask[0].numpy())
    assert cyc == sorted(len(densify(p, 0.05)) for p in scene.obstacles)


def test_batched_obstacle_graphs_equal_single_ones():
    scenes = [gp.make_scene("e", seed=s) for s in range(4)]
    polys, sizes = scene_obstacles(scenes)
    batch = obstacle_graph(polys, sizes)
    for i, s in enumerate(scenes):
        one = obstacle_graph(*scene_obstacles([s]))
        n = int(one.mask.sum())
        assert int(batch.mask[i].sum()) == n
        assert torch.equal(batch.nodes[i, :n], one.nodes[0, :n])
        assert torch.equal(batch.next[i, :n], one.next[0, :n])


@pytest.mark.parametrize("max_edge", [None, 0.05])
def test_robot_graph_positions_and_jacobians(max_edge):
    robot = gp.make_scene("d").robot
    graph = robot_graph(robot, max_edge)
    q = robot.sample(3, seed=1)
    p, jac = graph.positions_and_jacobians(q)
    if max_edge is None:
        np.testing.assert_allclose(p, robot.node_positions(q))
        np.testing.assert_allclose(jac, robot.node_jacobians(q))
    else:
        assert graph.n_nodes > robot.n_nodes
        edges = np.linalg.norm(p[:, graph.next] - p, axis=-1)
        assert edges.max() <= max_edge + 1e-9
    eps = 1e-6
    for j in range(robot.dof):
        dq = np.zeros(robot.dof)
        dq[j] = eps
        fd = (graph.positions(q + dq) - graph.positions(q - dq)) / (2 * eps)
        np.testing.assert_allclose(jac[..., j], fd, atol=1e-7)
    cyc = ring_cycles(graph.prev, graph.next, np.ones(graph.n_nodes, bool))
    assert len(cyc) == robot.n_links


@pytest.mark.parametrize(("env", "max_edge"), [("c", None), ("c", 0.1), ("fetch", None)])
def test_batch_kinematics_and_pullback_equal_pinocchio(env, max_edge):
    robot = gp.make_scene(env).robot
    q = robot.sample(5, seed=2)
    nodes, joints = robot_graph(robot).kinematics(q)
    np.testing.assert_allclose(nodes, robot.node_positions_pinocchio(q), atol=1e-12)
    np.testing.assert_allclose(joints, robot.chain.joint_positions(q), atol=1e-12)
    graph = robot_graph(robot, max_edge)
    nodes, joints = graph.kinematics(q)
    grad = np.random.default_rng(0).normal(size=nodes.shape)
    _, jac = graph.positions_and_jacobians(q)
    if max_edge is None:
        np.testing.assert_allclose(jac, robot.node_jacobians_pinocchio(q), atol=1e-12)
    expected = np.einsum("bni,bnij->bj", grad, jac)
    np.testing.assert_allclose(graph.pullback(nodes, joints, grad), expected, atol=1e-12)


def test_collate_pads_graphs_of_different_sizes():
    a = (np.zeros((3, 2)), np.array([2, 0, 1]), np.array([1, 2, 0]))
    b = (np.ones((5, 2)), np.array([4, 0, 1, 2, 3]), np.array([1, 2, 3, 4, 0]))
    g = collate([a, b])
    assert isinstance(g, GraphBatch)
    assert g.nodes.shape == (2, 5, 2)
    assert g.mask.sum(1).tolist() == [3, 5]
    assert g.next[0].tolist() == [1, 2, 0, 3, 4]
    sub = g.index(torch.tensor([0]))
    assert sub.nodes.shape == (1, 3, 2)


def test_bad_inputs_raise_input_error():
    polys = np.zeros((1, 1, 4, 2))
    with pytest.raises(gp.InputError):
        obstacle_graph(polys[0], np.array([4]))
    with pytest.raises(gp.InputError):
        obstacle_graph(polys, np.array([[5]]))
    with pytest.raises(gp.InputError):
        obstacle_graph(polys, np.array([[2]]))
    nan = polys.copy()
    nan[0, 0, 0, 0] = np.nan
    with pytest.raises(gp.InputError):
        obstacle_graph(nan, np.array([[4]]))
    with pytest.raises(gp.InputError):
        obstacle_graph(polys, np.array([[4]]), max_edge=-1.0)
    with pytest.raises(gp.InputError):
        scene_obstacles([gp.make_scene("a").with_obstacles([])])
    with pytest.raises(gp.InputError):
        collate([])
    with pytest.raises(gp.InputError):
        robot_graph(gp.make_scene("a").robot).positions(np.zeros(3))


def test_rings_handles_all_empty_rows():
    nodes, _, _, mask = rings(np.zeros((2, 1, 3, 2)), np.zeros((2, 1, 3), bool))
    assert nodes.shape == (2, 1, 2) and not mask.any()


def test_graph_reexports_the_concept_modules_names():
    """gdnplan.graph keeps every name it had: the same objects as the concept modules'."""
    import gdnplan.graph as graph
    from gdnplan import graph_batch, graph_obstacles, graph_robot

    for module in (graph_batch, graph_obstacles, graph_robot):
        for name in module.__all__:
            assert getattr(graph, name) is getattr(module, name), name
    assert set(graph.__all__) == {
        n for m in (graph_batch, graph_obstacles, graph_robot) for n in m.__all__
    }
    assert graph._rotate is graph_robot._rotate
