"""gdnplan.data.generate's bounds: n ≤ MAX_SPLIT and workers an int in 1 … MAX_WORKERS, checked
before anything is planned or written (a huge n used to run silently while memory grew)."""


import pytest
from tqdm import tqdm
from typer.testing import CliRunner

from gdnplan.cli import app
from gdnplan.data import generate
from gdnplan.data.shard_folder import MAX_SPLIT, MAX_WORKERS, check_split, run_jobs
from gdnplan.data.shards3d import generate3d
from gdnplan.errors import InputError


@pytest.mark.parametrize("n", [MAX_SPLIT + 1, 99999999999999, 0, -3, True, 2.5, "10"])
def test_a_split_outside_1_to_max_split_is_refused_at_once(tmp_path, n):
    out = tmp_path / "b"
    with pytest.raises(InputError, match="n: expected a number of samples in"):
        generate("b", n, 0, out, workers=1)
    assert not out.exists()  # refused before any work: no folder, no shard


@pytest.mark.parametrize("workers", [0, -1, True, False, 1.0, "2", MAX_WORKERS + 1])
def test_bad_workers_are_refused_by_name(tmp_path, workers):
    with pytest.raises(InputError, match="workers"):
        generate("b", 5, 0, tmp_path / "b", workers=workers)
    with pytest.raises(InputError, match="workers"):
        generate3d("ur5e_boxes", 5, 0, tmp_path / "u", workers=workers)
    with pytest.raises(InputError, match="workers"):
        run_jobs(lambda job: 0, [1], workers, tqdm(disable=True))
    assert not (tmp_path / "b").exists() and not (tmp_path / "u").exists()


@pytest.mark.parametrize("near", [float("nan"), -0.1, 1.5, "0.5", None])
def test_bad_near_is_refused(near):
    with pytest.raises(InputError, match="near"):
        check_split(10, near)


def test_the_largest_split_is_accepted_by_the_check():
    check_split(MAX_SPLIT, 0.0, 1)
    check_split(1, 1.0, None)


def test_cli_refuses_a_huge_n_quickly(tmp_path):
    args = ["generate", "--env", "b", "--n", "99999999999999", "--workers", "1"]
    r = CliRunner().invoke(app, [*args, "--data", str(tmp_path)])
    assert r.exit_code == 2
    assert not any(tmp_path.rglob("shard_*.npz"))  # refused before any work


def test_a_tiny_split_with_one_worker_is_written(tmp_path):
    out = generate("b", 3, 0, tmp_path / "b", workers=1)
    assert len(list(out.glob("shard_*.npz"))) == 1
