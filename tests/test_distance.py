"""coal ground truth against independent geometry: shapely distances and separating-axis depths."""

import numpy as np
import pytest
import shapely
from shapely.geometry import MultiPolygon, Polygon

import gdnplan as gp

ENVS = ["a", "b", "c", "d", "e"]


def sat_depth(a: np.ndarray, b: np.ndarray) -> float:
    """Translational penetration depth of two convex polygons by the separating-axis theorem:
    the smallest overlap of their projections over all edge normals (≤ 0 when separated)."""
    depth = np.inf
    for poly in (a, b):
        edges = np.roll(poly, -1, 0) - poly
        normals = np.stack([edges[:, 1], -edges[:, 0]], 1)
        normals /= np.linalg.norm(normals, axis=1, keepdims=True)
        for n in normals:
            pa, pb = a @ n, b @ n
            depth = min(depth, min(pa.max() - pb.min(), pb.max() - pa.min()))
    return depth


def independent_distance(scene: gp.Scene, q: np.ndarray) -> float:
    """Shapely distance when apart; minus the largest SAT depth over overlapping convex pairs."""
    links = scene.robot.link_polygons(q)
    gap = MultiPolygon([Polygon(p) for p in links]).distance(
        shapely.union_all([Polygon(o) for o in scene.obstacles])
    )
    if gap > 0:
        return gap
    return -max(sat_depth(link, part) for link in links for part in scene.obstacle_parts)


@pytest.mark.parametrize("env", ENVS)
def test_signed_distance_matches_shapely_and_sat(env):
    scene = gp.make_scene(env, seed=11)
    q = scene.robot.sample(1000, seed=3)
    d = gp.signed_distance(scene, q)
    expected = np.array([independent_distance(scene, qi) for qi in q])
    assert (d < 0).sum() > 20 and (d > 0).sum() > 20
    np.testing.assert_allclose(d, expected, atol=1e-6)


def test_axis_aligned_overlap_depth_is_analytic():
    """planar2 straight along +x through a square [0.5, 0.8] x [-0.1, 0.2]: the link (y in
    [-0.03, 0.03]) is deepest pushed out along y by 0.03 + 0.1 = 0.13 m."""
    robot = gp.load_robot("planar2")
    box = [[0.5, -0.1], [0.8, -0.1], [0.8, 0.2], [0.5, 0.2]]
    scene = gp.Scene(robot, (np.array(box),))
    assert gp.signed_distance(scene, np.zeros(2))[0] == pytest.approx(-0.13, abs=1e-9)


def test_per_link_distance_and_gradient():
    scene = gp.make_scene("d", seed=2)
    q = scene.robot.sample(300, seed=1)
    d_links, g_links = gp.signed_distance_and_grad(scene, q, per_link=True)
    d, _ = gp.signed_distance_and_grad(scene, q)
    assert d_links.shape == (300, 7) and g_links.shape == (300, 7, 7)
    np.testing.assert_allclose(d_links.min(1), d, atol=1e-12)
    # a link's distance never depends on joints downstream of it
    for k in range(7):
        assert np.all(g_links[:, k, k + 1 :] == 0)
    # its gradient against central differences: tests/test_gradients.py


def test_distance_is_batch_consistent_and_rejects_bad_q():
    scene = gp.make_scene("e", seed=1)
    q = scene.robot.sample(20, seed=0)
    batch = gp.signed_distance(scene, q)
    single = np.array([gp.signed_distance(scene, qi)[0] for qi in q])
    np.testing.assert_array_equal(batch, single)
    with pytest.raises(gp.InputError, match="q"):
        gp.signed_distance(scene, np.zeros((3, 2)))
    with pytest.raises(gp.InputError, match="NaN"):
        gp.signed_distance(scene, np.full(7, np.nan))


def test_coal_model_implements_the_protocol():
    model = gp.CoalModel()
    assert isinstance(model, gp.DistanceModel)
    scene = gp.make_scene("b", seed=0)
    d, g = model.distance_and_grad(scene, scene.robot.sample(4))
    assert d.shape == (4,) and g.shape == (4, 2)
