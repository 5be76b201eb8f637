"""UR5e samples (gdnplan.data.ur5e_samples): coal labels, robot variants, near-contact samples."""

import numpy as np
import pytest

import gdnplan as gp
from gdnplan import data
from gdnplan.ur5e import GRIPPER_STATES


def test_ur5e_shard_labels_match_coal_and_robots_vary():
    ds = data.make_shard("ur5e", seed=1, start=0, n=8)
    assert ds.gripper is not None and ds.stick.shape == (8, 2)
    assert set(np.unique(ds.gripper)) <= {0, 1, 2}
    for i in range(len(ds)):
        scene = ds.scene(i)
        held = GRIPPER_STATES[ds.gripper[i]] == "holding"
        assert ("stick" in [p.name for p in scene.robot.polygons]) == held
        if held:
            info = scene.robot.info
            assert (info["stick_length"], info["stick_width"]) == tuple(ds.stick[i])
            assert 0.15 <= ds.stick[i, 0] <= 0.30 and 0.02 <= ds.stick[i, 1] <= 0.04
        d, g = gp.signed_distance_and_grad(scene, ds.q[i])
        assert ds.d[i] == pytest.approx(d[0], abs=1e-9)
        np.testing.assert_allclose(ds.grad[i], g[0], atol=1e-9)
        k = scene.robot.n_nodes
        np.testing.assert_allclose(
            ds.nodes[i, :k], scene.robot.node_positions(ds.q[i])[0], atol=1e-6
        )
        assert not ds.nodes[i, k:].any()
    # layouts of a split come from its own pool, disjoint from the benchmark's seeds
    assert np.all(np.isin(ds.scene_seed, data.ur5e_layout_seeds(1)))


def test_ur5e_shards_roundtrip_with_their_robot_variants(tmp_path):
    ds = data.make_shard("ur5e", seed=1, start=0, n=6)
    ds.save(tmp_path / "shard_0000.npz")
    back = data.load(tmp_path)
    np.testing.assert_array_equal(back.gripper, ds.gripper)
    np.testing.assert_array_equal(back.stick, ds.stick)
    sub = back.subset(np.array([4, 1]))
    np.testing.assert_array_equal(sub.gripper, ds.gripper[[4, 1]])
    assert sum(len(rows) for rows in back.variants().values()) == 6


def test_ur5e_near_contact_samples_spread_around_the_task_configurations(tmp_path):
    ds = data.make_shard("ur5e", seed=2, start=0, n=6, near=1.0)
    for i in range(len(ds)):
        scene = ds.scene(i)
        d, _ = gp.signed_distance_and_grad(scene, ds.q[i])
        assert ds.d[i] == pytest.approx(d[0], abs=1e-9)
        fetch = gp.make_scene("fetch", seed=int(ds.scene_seed[i]))
        refs = [fetch.info[k] for k in ("q_home", "q_pregrasp", "q_grasp", "q_lift", "q_out")]
        assert min(np.abs(ds.q[i] - r).max() for r in refs) < 6 * max(data.NEAR_SIGMA)
    with pytest.raises(gp.InputError):
        data.generate("d", 10, 0, tmp_path, near=1.5)
