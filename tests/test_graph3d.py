"""3-D graphs against independent truth: Pinocchio's shape placements, finite differences,
polytope counts (boxes, prisms, Euler's formula) and brute-force nearest neighbours."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from gdnplan.arm3d import box_obstacle, load_robot3d, random_boxes
from gdnplan.errors import InputError
from gdnplan.graph3d import (
    box_graphs,
    hull_edges,
    knn_edges,
    neighbourhoods,
    point_cloud_graph,
    robot_graph3d,
    scene_graph3d,
    shape_points,
)


@pytest.fixture(scope="module")
def ur5e():
    return load_robot3d("ur5e")


@pytest.fixture(scope="module")
def panda():
    return load_robot3d("panda")


@pytest.mark.parametrize("name", ["ur5e", "panda"])
def test_node_positions_match_pinocchio_shape_placements(name):
    robot = load_robot3d(name)
    g = robot_graph3d(robot)
    qs = robot.random_configurations(5, np.random.default_rng(0))
    p = g.positions(qs)
    for b, q in enumerate(qs):
        tf = robot.shape_placements(q)  # Pinocchio FK · the shapes' placements
        expect = np.concatenate(
            [
                shape_points(s.shape) @ t[:3, :3].T + t[:3, 3]
                for s, t in zip(robot.shapes, tf, strict=True)
            ]
        )
        np.testing.assert_allclose(p[b], expect, atol=1e-12)


@pytest.mark.parametrize("name", ["ur5e", "panda"])
def test_node_jacobians_match_finite_differences(name):
    robot = load_robot3d(name)
    g = robot_graph3d(robot)
    qs = robot.random_configurations(3, np.random.default_rng(1))
    p, jac = g.positions_and_jacobians(qs)
    np.testing.assert_allclose(p, g.positions(qs), atol=0)
    h = 1e-6
    for b, q in enumerate(qs):
        for j in range(robot.dof):
            e = np.zeros(robot.dof)
            e[j] = h
            fd = (g.positions(q + e) - g.positions(q - e))[0] / (2 * h)
            np.testing.assert_allclose(jac[b, :, :, j], fd, atol=1e-8)


def test_pullback_is_the_jacobian_transpose_product(ur5e):
    g = robot_graph3d(ur5e)
    qs = ur5e.random_configurations(4, np.random.default_rng(2))
    nodes, frames = g.kinematics(qs)
    _, jac = g.positions_and_jacobians(qs)
    grad = np.random.default_rng(3).normal(size=nodes.shape)
    expect = np.einsum("bni,bnij->bj", grad, jac)
    np.testing.assert_allclose(g.pullback(nodes, frames, grad), expect, atol=1e-12)


def test_robot_graph_counts_and_neighbourhoods(ur5e):
    g = robot_graph3d(ur5e, rim=8)
    # 13 cylinders (two rims of 8) and 3 boxes (8 corners)
    assert g.n_nodes == 13 * 16 + 3 * 8
    degree = g.nbr_mask.sum(1)
    assert np.all(degree == 3)  # prism and box vertices: two rim/face neighbours + one across
    assert np.all(g.nbr[~g.nbr_mask] == np.nonzero(~g.nbr_mask)[0])  # padding points to itself
    # edges never join two shapes
    shape_of = np.repeat(
        np.arange(len(ur5e.shapes)), [len(shape_points(s.shape)) for s in ur5e.shapes]
    )
    rows = np.repeat(np.arange(g.n_nodes)[:, None], g.nbr.shape[1], 1)
    assert np.all(shape_of[g.nbr[g.nbr_mask]] == shape_of[rows[g.nbr_mask]])


def test_box_has_twelve_edges_and_prism_three_per_rim_point():
    corners = np.array([[x, y, z] for x in (0, 1) for y in (0, 2) for z in (0, 3)], float)
    assert len(hull_edges(corners)) == 12
    t = 2 * np.pi * np.arange(7) / 7
    prism = np.concatenate([np.c_[np.cos(t), np.sin(t), np.full(7, z)] for z in (0.0, 1.0)])
    assert len(hull_edges(prism)) == 21


@settings(max_examples=30, deadline=None)
@given(st.integers(5, 40), st.integers(0, 10_000))
def test_hull_edges_of_points_in_general_position_satisfy_euler(n, seed):
    pts = np.random.default_rng(seed).normal(size=(n, 3))
    edges = hull_edges(pts)
    from scipy.spatial import ConvexHull

    v = len(ConvexHull(pts).vertices)
    assert len(edges) == 3 * v - 6  # a simplicial polytope: E = 3V − 6
    assert set(np.unique(edges)) == set(ConvexHull(pts).vertices)


def test_flat_points_are_an_input_error():
    with pytest.raises(InputError, match="flat"):
        hull_edges(np.c_[np.random.default_rng(0).normal(size=(10, 2)), np.zeros(10)])


@settings(max_examples=30, deadline=None)
@given(st.integers(2, 60), st.integers(1, 8), st.integers(0, 10_000))
def test_knn_edges_match_brute_force(n, k, seed):
    pts = np.random.default_rng(seed).normal(size=(n, 3))
    edges = {tuple(e) for e in knn_edges(pts, k)}
    d = np.linalg.norm(pts[:, None] - pts[None], axis=-1)
    np.fill_diagonal(d, np.inf)
    kk = min(k, n - 1)
    expect = set()
    for i in range(n):
        for j in np.argsort(d[i])[:kk]:
            expect.add((min(i, j), max(i, j)))
    assert edges == expect


def test_neighbourhoods_pad_to_the_largest_degree():
    nbr, mask = neighbourhoods(4, np.array([[0, 1], [0, 2], [0, 3]]))
    assert nbr.shape == (4, 3) and mask.sum() == 6
    assert sorted(nbr[0]) == [1, 2, 3] and mask[0].all()
    assert nbr[1, 0] == 0 and not mask[1, 1:].any() and np.all(nbr[1, 1:] == 1)


def test_box_graphs_equal_the_scene_graph_of_the_same_boxes(ur5e):
    scene = random_boxes(ur5e, 5, seed=3)
    centers = np.array([o.pose.getTranslation() for o in scene.obstacles])
    sizes = np.array([2 * np.asarray(o.shape.halfSide) for o in scene.obstacles])
    a, b = box_graphs(centers, sizes), scene_graph3d(scene)
    np.testing.assert_allclose(a.nodes, b.nodes, atol=1e-12)
    np.testing.assert_array_equal(a.nbr, b.nbr)
    np.testing.assert_array_equal(a.nbr_mask, b.nbr_mask)


def test_rotated_box_nodes_are_its_corners(ur5e):
    rot = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    o = box_obstacle((0.1, 0.2, 0.15), (0.5, 0.0, 0.2), rot)  # sides ≤ FACE_SPACING: corners
    g = scene_graph3d(type("S", (), {"obstacles": (o,)})())
    local = (g.nodes - [0.5, 0.0, 0.2]) @ rot  # back in the box frame
    np.testing.assert_allclose(np.sort(np.abs(local), 0)[0], [0.05, 0.1, 0.075], atol=1e-12)


def test_point_cloud_graph_and_bad_clouds():
    cloud = np.random.default_rng(0).uniform(size=(50, 3))
    g = point_cloud_graph(cloud, k=4)
    assert g.n_nodes == 50 and np.all(g.nbr_mask.sum(1) >= 4)
    for bad in (np.zeros((5, 2)), np.full((3, 3), np.nan), np.zeros((0, 3))):
        with pytest.raises(InputError, match="points"):
            point_cloud_graph(bad)


def test_scene_graph_joins_obstacles_and_clouds(ur5e):
    scene = random_boxes(ur5e, 3, seed=0)
    cloud = np.random.default_rng(0).uniform(size=(30, 3))
    g = scene_graph3d(scene, clouds=[cloud], k=6)
    assert g.n_nodes == 24 + 30
    assert np.all(g.nbr[24:][g.nbr_mask[24:]] >= 24)  # cloud edges stay in the cloud
    assert np.all(g.nbr[:24][g.nbr_mask[:24]] < 24)


def test_octree_obstacles_are_the_knn_graph_of_their_voxels(ur5e):
    import coal

    from gdnplan.arm3d import Scene3D, obstacle

    pts = np.random.default_rng(0).uniform(-0.1, 0.1, (200, 3))
    tree = coal.makeOctree(pts, 0.02)
    scene = Scene3D(ur5e, [obstacle(tree, (0.5, 0.0, 0.3), name="cloud")])
    g = scene_graph3d(scene, k=5)
    centres = np.asarray(tree.toBoxes())[:, :3] + [0.5, 0.0, 0.3]
    np.testing.assert_allclose(g.nodes, centres, atol=1e-12)
    knn = point_cloud_graph(centres, 5)
    np.testing.assert_array_equal(g.nbr, knn.nbr)
    # every voxel centre lies within half a voxel diagonal of a cloud point
    shifted = pts + np.array([0.5, 0.0, 0.3])
    near = np.linalg.norm(centres[:, None] - shifted[None], axis=-1).min(1)
    assert near.max() <= 0.02 * np.sqrt(3) / 2 + 1e-9


def test_graph3d_reexports_the_concept_modules_names():
    """gdnplan.graph3d keeps every name it had: the same objects as the concept modules'."""
    import gdnplan.graph3d as graph3d
    from gdnplan import graph3d_obstacles, graph3d_robot, graph3d_shapes

    modules = (graph3d_shapes, graph3d_robot, graph3d_obstacles)
    for module in modules:
        for name in module.__all__:
            assert getattr(graph3d, name) is getattr(module, name), name
    assert set(graph3d.__all__) == {n for m in modules for n in m.__all__}
