"""Datasets (gdnplan.data.dataset): saving, loading and joining."""

import numpy as np
import pytest

import gdnplan as gp
from gdnplan import data


def test_compact_save_roundtrip(tmp_path):
    ds = data.make_shard("e", seed=0, start=0, n=4)
    ds.save(tmp_path / "x.npz", compact=True)
    back = data.load(tmp_path / "x.npz")
    np.testing.assert_allclose(back.obstacles, ds.obstacles, atol=1e-6)
    np.testing.assert_array_equal(back.d, ds.d)


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
