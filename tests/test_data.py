"""Datasets: deterministic shards, coal labels, resumable generation, loading, bad input."""

import numpy as np
import pytest

import gdnplan as gp
from gdnplan import data
from gdnplan.errors import InputError
from gdnplan.ur5e import GRIPPER_STATES


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


def test_generate_is_resumable_and_load_concatenates(tmp_path, monkeypatch):
    monkeypatch.setattr(data, "SHARD_SIZE", 4)
    out = tmp_path / "b"
    data.generate("b", 10, seed=1, out_dir=out, workers=1)
    files = sorted(out.glob("shard_*.npz"))
    assert len(files) == 3
    stamps = [f.stat().st_mtime_ns for f in files]
    files[1].unlink()
    data.generate("b", 10, seed=1, out_dir=out, workers=1)
    assert [f.stat().st_mtime_ns for f in sorted(out.glob("shard_*.npz"))][::2] == stamps[::2]
    ds = data.load(out)
    assert len(ds) == 10 and ds.env == "b"
    shards = [data.make_shard("b", seed=1, start=s, n=min(4, 10 - s)) for s in (0, 4, 8)]
    np.testing.assert_array_equal(ds.scene_seed, np.arange(10) + 10**8)
    np.testing.assert_allclose(ds.d, np.concatenate([s.d for s in shards]))
    assert len(data.load(out, n=5)) == 5


def test_compact_save_roundtrip(tmp_path):
    ds = data.make_shard("e", seed=0, start=0, n=4)
    ds.save(tmp_path / "x.npz", compact=True)
    back = data.load(tmp_path / "x.npz")
    np.testing.assert_allclose(back.obstacles, ds.obstacles, atol=1e-6)
    np.testing.assert_array_equal(back.d, ds.d)


def test_bad_inputs_raise(tmp_path):
    with pytest.raises(gp.UnknownNameError):
        data.generate("z", 10, 0, tmp_path)
    with pytest.raises(gp.InputError):
        data.generate("a", 0, 0, tmp_path)
    with pytest.raises(gp.InputError):
        data.load("/nonexistent/dir")


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


def test_concat_pads_polygons_and_rejects_mixed_environments():
    a = data.make_shard("b", seed=4, start=0, n=3)
    b = data.make_shard("b", seed=4, start=3, n=2)
    both = data.concat([a, b])
    assert len(both) == 5 and both.obstacles.shape[1:3] == (
        max(a.obstacles.shape[1], b.obstacles.shape[1]),
        max(a.obstacles.shape[2], b.obstacles.shape[2]),
    )
    for i, (ds, j) in enumerate([(a, 0), (a, 1), (a, 2), (b, 0), (b, 1)]):
        assert [p.tolist() for p in both.scene(i).obstacles] == [
            p.tolist() for p in ds.scene(j).obstacles
        ]
    with pytest.raises(gp.InputError):
        data.concat([a, data.make_shard("a", seed=4, start=0, n=2)])


def _arrays(path):
    ds = data.load(path)
    return {f: getattr(ds, f) for f in data.FIELDS}


@pytest.mark.parametrize("sizes", [(3, 7), (4, 9), (1, 2, 8), (5, 5)])
def test_resume_with_a_larger_n_equals_a_one_shot_run(tmp_path, monkeypatch, sizes):
    """generate n₁ then n₂ > n₁ into one folder = generate n₂ once (same shards, same samples)."""
    monkeypatch.setattr(data, "SHARD_SIZE", 4)
    once, resumed = tmp_path / "once", tmp_path / "resumed"
    data.generate("a", sizes[-1], seed=2, out_dir=once, workers=1)
    for n in sizes:
        data.generate("a", n, seed=2, out_dir=resumed, workers=1)
    names = sorted(p.name for p in once.iterdir())
    assert sorted(p.name for p in resumed.iterdir()) == names
    assert "manifest.json" in names and not [n for n in names if n.startswith(".")]
    a, b = _arrays(once), _arrays(resumed)
    assert len(b["q"]) == sizes[-1]
    for f in data.FIELDS:
        np.testing.assert_array_equal(a[f], b[f], err_msg=f)


def test_resume_keeps_complete_shards_and_remakes_the_short_last_one(tmp_path, monkeypatch):
    monkeypatch.setattr(data, "SHARD_SIZE", 4)
    data.generate("a", 6, seed=0, out_dir=tmp_path, workers=1)  # shards of 4 and 2
    first, second = tmp_path / "shard_0000.npz", tmp_path / "shard_0001.npz"
    stamps = first.stat().st_mtime_ns, second.stat().st_mtime_ns
    data.generate("a", 8, seed=0, out_dir=tmp_path, workers=1)
    assert first.stat().st_mtime_ns == stamps[0] and second.stat().st_mtime_ns != stamps[1]
    assert len(data.load(tmp_path)) == 8


@pytest.mark.parametrize(
    ("change", "option"),
    [({"env": "c"}, "--env"), ({"seed": 1}, "--seed"), ({"near": 0.5}, "--near")],
)
def test_resume_with_other_settings_is_refused(tmp_path, monkeypatch, change, option):
    monkeypatch.setattr(data, "SHARD_SIZE", 4)
    settings = {"env": "a", "seed": 0, "near": 0.0}
    data.generate(n=5, out_dir=tmp_path, workers=1, **settings)
    before = {p.name: p.stat().st_mtime_ns for p in tmp_path.iterdir()}
    with pytest.raises(InputError, match=f"^{option}: .*manifest.json"):
        data.generate(n=9, out_dir=tmp_path, workers=1, **(settings | change))
    assert {p.name: p.stat().st_mtime_ns for p in tmp_path.iterdir()} == before


def test_a_smaller_n_and_unrecorded_shards_are_refused(tmp_path, monkeypatch):
    monkeypatch.setattr(data, "SHARD_SIZE", 4)
    data.generate("a", 9, seed=0, out_dir=tmp_path, workers=1)
    for n in (8, 5, 3):  # fewer shards, or a shorter last shard
        with pytest.raises(InputError, match=r"^--n: .*holds 9 samples.*n ≥ 9"):
            data.generate("a", n, seed=0, out_dir=tmp_path, workers=1)
    assert len(data.load(tmp_path)) == 9
    (tmp_path / "manifest.json").unlink()
    with pytest.raises(InputError, match=r"no manifest\.json"):
        data.generate("a", 9, seed=0, out_dir=tmp_path, workers=1)
    (tmp_path / "manifest.json").write_text("[1, 2")
    with pytest.raises(InputError, match="not a readable manifest"):
        data.generate("a", 9, seed=0, out_dir=tmp_path, workers=1)


def test_an_interrupted_shard_leaves_no_temp_and_is_made_on_resume(tmp_path, monkeypatch):
    monkeypatch.setattr(data, "SHARD_SIZE", 4)
    real = np.savez_compressed

    def interrupted(f, **arrays):
        f.write(b"PK\x03\x04 half a zip")
        raise KeyboardInterrupt

    monkeypatch.setattr(np, "savez_compressed", interrupted)
    with pytest.raises(KeyboardInterrupt):
        data.generate("a", 6, seed=0, out_dir=tmp_path, workers=1)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["manifest.json"]
    monkeypatch.setattr(np, "savez_compressed", real)
    data.generate("a", 6, seed=0, out_dir=tmp_path, workers=1)
    assert len(data.load(tmp_path)) == 6
