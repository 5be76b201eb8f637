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


@pytest.mark.parametrize("env", ["a", "b"])  # fixed scene, one scene per sample
def test_test_set_without_data_equals_the_generated_shards(tmp_path, monkeypatch, env):
    """`evaluate.test_set` with no data/ and `gdnplan generate` give the same samples, in the
    first shard and in later ones (blocks of 4 here: samples 0–3, 4–7, 8–9)."""
    from gdnplan import metrics

    monkeypatch.setattr(data.sampling, "SHARD_SIZE", 4)
    root = tmp_path / "data"
    drawn = metrics.test_set(env, 10, root=root)  # no data/: labelled here
    data.generate(env, 10, seed=1, out_dir=data.split_dir(env, "test", root), workers=1)
    read = metrics.test_set(env, 10, root=root)  # from the shards
    assert len(read) == len(drawn) == 10
    for f in data.FIELDS:
        np.testing.assert_array_equal(getattr(drawn, f), getattr(read, f), err_msg=f)
    # a later block differs from the first (not one stream restarted per shard)
    assert not np.allclose(drawn.q[4:8], drawn.q[:4])
    np.testing.assert_array_equal(drawn.scene_seed, 10**8 + np.arange(10))


def test_split_samples_of_any_range_are_the_split_s():
    """A range that starts and ends inside blocks is the same samples as the whole split."""
    import gdnplan.data.sampling as sampling

    whole = sampling.split_samples("c", 1, 0, 12)
    old = sampling.SHARD_SIZE
    try:
        sampling.SHARD_SIZE = 5
        blocks = sampling.split_samples("c", 1, 0, 12)
        part = sampling.split_samples("c", 1, 3, 8)
    finally:
        sampling.SHARD_SIZE = old
    np.testing.assert_array_equal(blocks.q[3:11], part.q)
    np.testing.assert_array_equal(blocks.d[3:11], part.d)
    assert not np.allclose(whole.q[5:10], blocks.q[5:10])  # the blocks are the sampling unit
    with pytest.raises(gp.InputError):
        sampling.split_samples("c", 1, 0, 0)
