"""Writing splits (gdnplan.data.shards): resumable generation, manifests, bad input."""

import numpy as np
import pytest

import gdnplan as gp
from gdnplan import data
from gdnplan.errors import InputError


def _arrays(path):
    ds = data.load(path)
    return {f: getattr(ds, f) for f in data.FIELDS}


def test_generate_is_resumable_and_load_concatenates(tmp_path, monkeypatch):
    monkeypatch.setattr(data.sampling, "SHARD_SIZE", 4)
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
    with pytest.warns(UserWarning, match="holds 10 samples, fewer than the 11 asked for"):
        assert len(data.load(out, n=11)) == 10  # audit: a larger --n-train was silent


def test_bad_inputs_raise(tmp_path):
    with pytest.raises(gp.UnknownNameError):
        data.generate("z", 10, 0, tmp_path)
    with pytest.raises(gp.InputError):
        data.generate("a", 0, 0, tmp_path)
    with pytest.raises(gp.InputError):
        data.load("/nonexistent/dir")


@pytest.mark.parametrize("sizes", [(3, 7), (4, 9), (1, 2, 8), (5, 5)])
def test_resume_with_a_larger_n_equals_a_one_shot_run(tmp_path, monkeypatch, sizes):
    """generate n₁ then n₂ > n₁ into one folder = generate n₂ once (same shards, same samples)."""
    monkeypatch.setattr(data.sampling, "SHARD_SIZE", 4)
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
    monkeypatch.setattr(data.sampling, "SHARD_SIZE", 4)
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
    monkeypatch.setattr(data.sampling, "SHARD_SIZE", 4)
    settings = {"env": "a", "seed": 0, "near": 0.0}
    data.generate(n=5, out_dir=tmp_path, workers=1, **settings)
    before = {p.name: p.stat().st_mtime_ns for p in tmp_path.iterdir()}
    with pytest.raises(InputError, match=f"^{option}: .*manifest.json"):
        data.generate(n=9, out_dir=tmp_path, workers=1, **(settings | change))
    assert {p.name: p.stat().st_mtime_ns for p in tmp_path.iterdir()} == before


def test_a_smaller_n_and_unrecorded_shards_are_refused(tmp_path, monkeypatch):
    monkeypatch.setattr(data.sampling, "SHARD_SIZE", 4)
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
    monkeypatch.setattr(data.sampling, "SHARD_SIZE", 4)
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


@pytest.mark.parametrize("offset", [0, 1, 2**64])
def test_split_seeds_are_bounded_so_scene_seeds_stay_64_bit(tmp_path, offset):
    """Sample i of split seed s draws its scene with seed s · 10⁸ + i (int64): the largest
    allowed seed works to the last sample of a split, larger ones are InputErrors naming
    ``seed`` (they overflowed in numpy: OverflowError)."""
    from gdnplan.data.sampling import split_samples
    from gdnplan.data.shard_folder import MAX_DATA_SEED, MAX_SPLIT, SCENE_SEED_STRIDE

    assert MAX_DATA_SEED * SCENE_SEED_STRIDE + MAX_SPLIT <= np.iinfo(np.int64).max
    seed = MAX_DATA_SEED + offset
    if offset:
        for call in (
            lambda: data.generate("d", 1, seed, tmp_path / "x", workers=1),
            lambda: split_samples("d", seed, 0, 1),
        ):
            with pytest.raises(InputError, match=r"^seed: expected an integer in \[0, "):
                call()
    else:
        assert len(split_samples("d", seed, MAX_SPLIT - 1, 1).q) == 1


def test_ctrl_c_stops_a_pool_of_workers_at_once_with_one_line(tmp_path):
    """Audit: Ctrl-C (SIGINT to the process group) during `gdnplan generate --workers 2` made
    every worker print a KeyboardInterrupt traceback, and the command ended only when the
    workers' shards were done (~40 s for (d)); no half shard may be left either."""
    import os
    import signal
    import subprocess
    import sys
    import time

    cmd = [sys.executable, "-m", "gdnplan", "generate", "--env", "d", "--n", "20000"]
    cmd += ["--workers", "2", "--data", str(tmp_path)]
    proc = subprocess.Popen(
        cmd,
        stderr=subprocess.PIPE,
        stdout=subprocess.DEVNULL,
        start_new_session=True,
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
    )
    manifest = tmp_path / "d" / "train" / "manifest.json"
    deadline = time.monotonic() + 60
    while not manifest.exists() and time.monotonic() < deadline:
        time.sleep(0.1)
    time.sleep(1.0)  # the workers are inside their first shard
    start = time.monotonic()
    os.killpg(proc.pid, signal.SIGINT)
    try:
        _, err = proc.communicate(timeout=20)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        raise
    assert proc.returncode == 130 and time.monotonic() - start < 10
    text = err.decode()
    assert "Traceback" not in text and text.rstrip().endswith("error: interrupted")
    assert not list((tmp_path / "d" / "train").glob("shard_*.npz"))


def _worker_sigint(job: int) -> int:
    import signal

    return int(signal.getsignal(signal.SIGINT) is signal.SIG_IGN)


def test_pool_workers_leave_ctrl_c_to_the_parent():
    """The deterministic half of the test above: every worker ignores SIGINT (a worker that
    took it printed its traceback, or raced the parent's terminate)."""
    from gdnplan.data.shard_folder import run_jobs

    class Bar:  # counts what the workers return (1: SIGINT ignored)
        n = 0

        def update(self, k: int) -> None:
            self.n += k

    bar = Bar()
    run_jobs(_worker_sigint, [0, 1, 2, 3], 2, bar)
    assert bar.n == 4
