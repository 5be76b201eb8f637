"""Shards of a–e (gdnplan.data.sampling): deterministic, coal labels, near-boundary samples."""

import numpy as np
import pytest

import gdnplan as gp
from gdnplan import data


def test_shard_is_deterministic_and_labels_match_coal():
    a = data.make_shard("d", seed=3, start=10, n=6)
    b = data.make_shard("d", seed=3, start=10, n=6)
    np.testing.assert_array_equal(a.q, b.q)
    np.testing.assert_array_equal(a.obstacles, b.obstacles)
    for i in range(len(a)):
        scene = gp.make_scene("d", seed=int(a.scene_seed[i]))
        d, g = gp.signed_distance_and_grad(scene, a.q[i])
        assert a.d[i] == pytest.approx(d[0])
        np.testing.assert_allclose(a.grad[i], g[0])
        np.testing.assert_allclose(a.scene(i).obstacles[0], scene.obstacles[0])
    np.testing.assert_allclose(a.nodes, gp.make_scene("d").robot.node_positions(a.q), atol=1e-6)


def test_random_envs_draw_a_scene_per_sample_and_fixed_ones_share_it():
    e = data.make_shard("e", seed=0, start=0, n=3)
    assert len({e.obstacles[i].tobytes() for i in range(3)}) == 3
    c = data.make_shard("c", seed=0, start=0, n=3)
    assert len({c.obstacles[i].tobytes() for i in range(3)}) == 1


@pytest.mark.parametrize("env", ["a", "d"])  # fixed scene, one scene per sample
def test_near_boundary_samples_lie_in_the_band_with_coal_labels(env):
    ds = data.make_shard(env, seed=3, start=0, n=40, near=0.5)
    near = np.abs(ds.d) < data.BOUNDARY_BAND
    uniform = data.make_shard(env, seed=3, start=0, n=40)
    assert near.sum() >= 10  # about half the samples, and uniform ones rarely fall in the band
    assert near.sum() > 3 * (np.abs(uniform.d) < data.BOUNDARY_BAND).sum()
    for i in range(0, 40, 7):
        d, g = gp.signed_distance_and_grad(ds.scene(i), ds.q[i])
        assert ds.d[i] == pytest.approx(d[0], abs=1e-9)
        np.testing.assert_allclose(ds.grad[i], g[0], atol=1e-9)
    robot = ds.robot(0)
    assert robot.within_limits(ds.q).all()
