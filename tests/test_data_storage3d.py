"""The ``ur5e_storage`` environment: coal labels of the fetch's scenes, both robot variants,
shards pure functions of their settings, the CLI and Ray writing the same bytes."""

from __future__ import annotations

import os

import numpy as np
import pytest

from gdnplan.arm3d import Checker3D
from gdnplan.arm3d.fetch3d_scene import fetch3d_scenes
from gdnplan.arm3d.held import HELD_LINK
from gdnplan.arm3d.storage3d import Placement, Storage3D, on_table
from gdnplan.cli import run
from gdnplan.data.samples3d import SCENE_SAMPLES, make_shard3d
from gdnplan.data.samples_storage3d import HOLDING, OPEN, storage_scene_of, without_self_pairs
from gdnplan.data.shards3d import generate3d


@pytest.fixture(scope="module")
def shard():
    return make_shard3d("ur5e_storage", 2, 0, 6 * SCENE_SAMPLES, near=0.3)


def test_storage_shards_are_pure_and_labelled_by_coal_of_the_fetch_scenes(shard):
    again = make_shard3d("ur5e_storage", 2, 0, 6 * SCENE_SAMPLES, near=0.3)
    assert all(np.array_equal(shard[k], again[k]) for k in shard)
    assert set(shard["variant"].tolist()) == {OPEN, HOLDING}  # both variants in 6 scenes
    for s in range(6):
        storage, placement = Storage3D(*shard["storage"][s]), Placement(*shard["placement"][s])
        assert on_table(storage, placement)
        scene = fetch3d_scenes(storage, placement)["holding" if shard["variant"][s] else "open"]
        names = [o.name for o in scene.obstacles]
        assert ("stick" in names) == (shard["variant"][s] == OPEN) and "table" in names
        holds = HELD_LINK in scene.robot.links
        assert holds == (shard["variant"][s] == HOLDING)
        rows = np.flatnonzero(shard["scene"] == s)
        labeller = Checker3D(type(scene)(without_self_pairs(scene.robot), list(scene.obstacles)))
        ref = labeller.evaluate(shard["q"][rows], gradient=True)
        np.testing.assert_allclose(shard["d"][rows], ref.distance, atol=1e-12)
        np.testing.assert_allclose(shard["grad"][rows], ref.gradient, atol=1e-9)
        built = storage_scene_of(shard["storage"][s], shard["placement"][s], shard["variant"][s])
        assert [o.name for o in built.obstacles] == names
    assert (shard["d"] < 0).any() and (shard["d"] > 0).any()


def _same(a, b) -> None:
    """The same shard: identical inputs; labels equal to within coal's solver tolerance (a
    process's history changes the last digits of coal's distance near contact, measured
    5e-11 m on a sample)."""
    assert a.files == b.files
    for k in a.files:
        if k in ("d", "grad"):
            np.testing.assert_allclose(a[k], b[k], rtol=0, atol=1e-8)
        else:
            assert np.array_equal(a[k], b[k]), k


def test_cli_and_ray_write_the_same_storage_shards(tmp_path):
    with pytest.raises(SystemExit) as e:
        run(
            [
                *("generate", "--env", "ur5e_storage", "--n", "100", "--workers", "1"),
                *("--data", str(tmp_path / "cli"), "--near", "0.2"),
            ]
        )
    assert e.value.code == 0
    cli = tmp_path / "cli" / "ur5e_storage" / "train"
    local = generate3d("ur5e_storage", 100, 0, tmp_path / "local", workers=1, near=0.2)
    names = sorted(p.name for p in local.glob("shard_*.npz"))
    assert len(names) == 1
    for name in names:
        with np.load(local / name) as a, np.load(cli / name) as b:
            _same(a, b)
    if os.environ.get("CI") != "true":
        pytest.importorskip("ray")
    ray = generate3d("ur5e_storage", 100, 0, tmp_path / "ray", near=0.2, ray="local")
    for name in names:  # the same arrays (the zip entries' timestamps are the writing time)
        with np.load(local / name) as a, np.load(ray / name) as b:
            _same(a, b)
