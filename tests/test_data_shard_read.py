"""Shards read back as untrusted input (gdnplan/data/shard_read.py): a damaged, foreign or
inconsistent shard is an InputError naming the file, never numpy's or zipfile's error from
inside a training run; generate makes a damaged shard again."""

from __future__ import annotations

import io
import zipfile

import numpy as np
import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

from gdnplan import data
from gdnplan.data.shard_read import MAX_SHARD_BYTES
from gdnplan.errors import InputError
from gdnplan.train.shard_stream3d import read_shard


@pytest.fixture(scope="module")
def shard(tmp_path_factory):
    """A good 6-sample shard of environment b, as arrays."""
    path = tmp_path_factory.mktemp("good") / "shard_0000.npz"
    data.make_shard("b", seed=0, start=0, n=6).save(path)
    with np.load(path) as z:
        return {k: z[k] for k in z.files}


def _nan(a):
    a["d"] = a["d"].copy()
    a["d"][2] = np.nan


DAMAGE = {
    "nan label": (_nan, "'d' holds NaN or inf"),
    "complex q": (lambda a: a.update(q=a["q"].astype(complex)), "'q' holds complex128"),
    "text d": (lambda a: a.update(d=a["d"].astype(str)), "'d' holds <U"),
    "q of one joint": (lambda a: a.update(q=a["q"][:, :1]), "has shape"),
    "short grad": (lambda a: a.update(grad=a["grad"][:3]), "'grad' has shape"),
    "no d": (lambda a: a.pop("d"), "'d' is missing"),
    "no env": (lambda a: a.pop("env"), "'env' is missing"),
    "object d": (lambda a: a.update(d=a["d"].astype(object)), "Python objects"),
    "float sizes": (lambda a: a.update(sizes=a["sizes"] + 0.5), "'sizes' holds float64"),
    "sizes beyond V": (lambda a: a.update(sizes=a["sizes"] + 99), "'sizes' holds vertex counts"),
    "flat obstacles": (lambda a: a.update(obstacles=a["obstacles"][..., 0]), "'obstacles'"),
}


@pytest.mark.parametrize("case", DAMAGE)
def test_a_damaged_shard_is_refused_naming_the_file(tmp_path, shard, case):
    damage, match = DAMAGE[case]
    arrays = {k: v.copy() for k, v in shard.items()}
    damage(arrays)
    path = tmp_path / "shard_0000.npz"
    np.savez(path, **arrays, allow_pickle=True) if case == "object d" else np.savez(path, **arrays)
    with pytest.raises(InputError, match=match) as info:
        data.load(tmp_path)
    assert str(path) in str(info.value) and "gdnplan generate" in str(info.value)


@settings(
    max_examples=10, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(keep=st.floats(0.0, 0.99))
@example(keep=0.5)  # a copy cut short: zipfile's BadZipFile was an internal error (exit 3)
def test_a_truncated_shard_is_refused_and_made_again_by_generate(tmp_path_factory, keep):
    out = tmp_path_factory.mktemp("split")
    data.generate("b", 6, seed=0, out_dir=out, workers=1)
    path = out / "shard_0000.npz"
    whole = path.read_bytes()
    path.write_bytes(whole[: int(len(whole) * keep)])
    with pytest.raises(InputError, match=r"shard_0000\.npz"):
        data.load(out)
    data.generate("b", 6, seed=0, out_dir=out, workers=1)  # the damaged shard is made again
    assert path.read_bytes() == whole


def test_a_header_claiming_more_than_the_limit_is_refused_before_reading(tmp_path):
    """A compressed array of zeros claims ~1000× its size on disk: the headers are summed
    before numpy allocates anything."""
    header = io.BytesIO()
    np.lib.format.write_array_header_1_0(
        header, {"descr": "<f8", "fortran_order": False, "shape": (MAX_SHARD_BYTES // 8 + 1,)}
    )
    path = tmp_path / "shard_0000.npz"
    with zipfile.ZipFile(path, "w") as zf:
        zf.writestr("q.npy", header.getvalue())  # the magic and header, no data
    for read in (data.load, read_shard):
        with pytest.raises(InputError, match=r"claims .* bytes of arrays, more than"):
            read(path)


def test_shards_of_two_environments_in_one_folder_are_refused(tmp_path):
    data.make_shard("b", seed=0, start=0, n=3).save(tmp_path / "shard_0000.npz")
    data.make_shard("d", seed=0, start=0, n=3).save(tmp_path / "shard_0001.npz")
    with pytest.raises(InputError, match=r"shard_0001\.npz holds samples of environment 'd'"):
        data.load(tmp_path)
