"""Atomic writes and output-path checks (gdnplan.files)."""

import errno
import os
import re
import signal
import socket
import stat
import subprocess
import sys

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from gdnplan.errors import GdnplanError, OutputError
from gdnplan.files import atomic_path, check_output_dir, check_output_path, write_text


def leftovers(directory) -> list[str]:
    return sorted(p.name for p in directory.iterdir() if p.name.startswith("."))


def test_atomic_write_replaces_the_target_with_the_usual_permissions(tmp_path):
    target = tmp_path / "a.txt"
    target.write_text("old")
    write_text(target, "new")
    assert target.read_text() == "new" and leftovers(tmp_path) == []
    mask = os.umask(0o022)
    os.umask(mask)
    assert target.stat().st_mode & 0o777 == 0o666 & ~mask


def test_the_temporary_name_keeps_the_suffix_for_format_sniffing_writers(tmp_path):
    with atomic_path(tmp_path / "x.npz") as tmp:
        assert tmp.parent == tmp_path and tmp.name.startswith(".x.npz.")
        assert tmp.name.endswith(".tmp.npz")
        np.savez(tmp, a=np.arange(3))  # would append .npz to another suffix
    with np.load(tmp_path / "x.npz") as z:
        assert z["a"].tolist() == [0, 1, 2]
    assert leftovers(tmp_path) == []


@pytest.mark.parametrize("failure", [RuntimeError("writer bug"), KeyboardInterrupt()])
def test_a_writer_failing_midway_leaves_the_old_target_and_no_temp(tmp_path, failure):
    target = tmp_path / "a.gif"
    target.write_bytes(b"old")
    with pytest.raises(type(failure)):
        with atomic_path(target) as tmp:
            tmp.write_bytes(b"x" * 65536)  # half a GIF
            raise failure
    assert target.read_bytes() == b"old" and leftovers(tmp_path) == []


def test_a_full_disk_is_a_one_line_error_and_leaves_no_temp(tmp_path, monkeypatch):
    def full(self, data):
        with open(self, "wb") as f:
            f.write(data[:100])
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(type(tmp_path), "write_bytes", full)
    with pytest.raises(OutputError, match="No space left"):
        with atomic_path(tmp_path / "a.png") as tmp:
            tmp.write_bytes(b"y" * 1000)
    assert list(tmp_path.iterdir()) == []


def test_a_failing_rename_leaves_no_temp(tmp_path, monkeypatch):
    def refuse(src, dst):
        raise OSError(errno.EXDEV, "cross-device link")

    monkeypatch.setattr(os, "replace", refuse)
    with pytest.raises(OutputError, match=r"a\.md"):
        write_text(tmp_path / "a.md", "text")
    assert list(tmp_path.iterdir()) == []


def test_sigterm_during_a_write_removes_the_temp(tmp_path):
    import gdnplan

    code = (  # a bare package: gdnplan.files without torch & co. (fast)
        "import os, signal, sys, types\n"
        "pkg = sys.modules['gdnplan'] = types.ModuleType('gdnplan')\n"
        f"pkg.__path__ = [{os.path.dirname(gdnplan.__file__)!r}]\n"
        "from gdnplan.files import atomic_path\n"
        f"with atomic_path({str(tmp_path / 'a.gif')!r}) as tmp:\n"
        "    tmp.write_bytes(b'x' * 1000)\n"
        "    os.kill(os.getpid(), signal.SIGTERM)\n"
        "    print('not reached')\n"
    )
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert run.returncode == 128 + signal.SIGTERM and "not reached" not in run.stdout
    assert list(tmp_path.iterdir()) == []
    assert signal.getsignal(signal.SIGTERM) is signal.SIG_DFL  # ours is restored (main thread)


def special_targets(tmp_path):
    """A symlink (to a regular file), a directory, a FIFO, a socket and a device node."""
    real = tmp_path / "real.png"
    real.write_bytes(b"keep")
    (tmp_path / "link.png").symlink_to(real)
    (tmp_path / "dir.png").mkdir()
    os.mkfifo(tmp_path / "fifo.png")
    sock = socket.socket(socket.AF_UNIX)
    sock.bind(str(tmp_path / "sock.png"))
    names = ["link.png", "dir.png", "fifo.png", "sock.png"]
    return [tmp_path / n for n in names] + [os.devnull], sock


def test_non_regular_targets_are_never_replaced(tmp_path):
    targets, sock = special_targets(tmp_path)
    try:
        for target in targets:
            before = os.lstat(target)
            with pytest.raises(OutputError, match=re.escape(str(target))):
                check_output_path(target, (".png",), "--out")
            with pytest.raises(OutputError, match=re.escape(str(target))):
                write_text(target, "x")
            after = os.lstat(target)
            assert (before.st_ino, before.st_mode) == (after.st_ino, after.st_mode)
        assert (tmp_path / "real.png").read_bytes() == b"keep"
        assert not [n for n in leftovers(tmp_path) if ".tmp" in n]
    finally:
        sock.close()


def test_check_output_path_rejects_unknown_suffixes_naming_the_allowed_ones(tmp_path):
    with pytest.raises(OutputError, match=r"--out: .*scene.*\.png or \.pdf"):
        check_output_path(tmp_path / "scene", (".png", ".pdf"), "--out")
    assert check_output_path(tmp_path / "scene.PNG", (".png",)) == tmp_path / "scene.PNG"


def test_check_output_path_rejects_bad_places_before_any_work(tmp_path):
    file = tmp_path / "file"
    file.write_text("")
    with pytest.raises(OutputError, match=r"(?i)not a directory"):
        check_output_path(file / "a.png", (".png",))
    with pytest.raises(OutputError, match=r"(?i)not a directory"):
        check_output_path(file / "sub" / "a.png", (".png",))
    with pytest.raises(OutputError, match="not writable"):
        check_output_path("/proc/a.png", (".png",))  # read-only even for root
    assert check_output_path(tmp_path / "new" / "dir" / "a.png", (".png",))  # created on write
    assert not (tmp_path / "new").exists() and leftovers(tmp_path) == []


def test_check_output_path_probes_writability(tmp_path, monkeypatch):
    import tempfile

    def denied(*args, **kwargs):
        raise PermissionError(errno.EACCES, "Permission denied")

    monkeypatch.setattr(tempfile, "mkstemp", denied)
    with pytest.raises(OutputError, match="not writable"):
        check_output_path(tmp_path / "a.png", (".png",))


@pytest.mark.skipif(os.geteuid() == 0, reason="root writes into read-only directories")
def test_check_output_path_rejects_a_read_only_directory(tmp_path):
    ro = tmp_path / "ro"
    ro.mkdir(mode=0o555)
    with pytest.raises(OutputError, match="not writable"):
        check_output_path(ro / "a.png", (".png",))


def test_check_output_dir(tmp_path):
    file = tmp_path / "file"
    file.write_text("")
    with pytest.raises(OutputError, match="not a directory"):
        check_output_dir(file)
    with pytest.raises(OutputError, match="not a directory"):
        check_output_dir(file / "sub")
    assert check_output_dir(tmp_path / "a" / "b") == tmp_path / "a" / "b"
    assert issubclass(OutputError, GdnplanError)


@settings(max_examples=20, deadline=None)
@given(st.integers(1, 400), st.booleans(), st.sampled_from(["dir", "file"]))
@example(300, False, "dir")  # the audit's case: fetch --3d --write-problems exited 3 (OSError)
@example(300, True, "dir")
def test_a_name_the_system_refuses_is_an_output_error(tmp_path_factory, length, nested, kind):
    """A path component longer than the file system allows (255 bytes here) is one
    OutputError naming the path, for a directory as for a file; shorter ones are accepted."""
    base = tmp_path_factory.mktemp("names")
    path = base / ("x" * length)
    path = path / "sub" if nested else path
    path = path.with_suffix(".png") if kind == "file" else path
    check = check_output_dir if kind == "dir" else lambda p: check_output_path(p, (".png",))
    if any(len(os.fsencode(part)) > 255 for part in path.relative_to(base).parts):
        with pytest.raises(OutputError, match="cannot write"):
            check(path)
    else:
        assert check(path) == path


def test_a_nul_byte_in_an_output_directory_is_an_output_error(tmp_path):
    with pytest.raises(OutputError, match="cannot write"):
        check_output_dir(tmp_path / "a\0b")


# ------------------------------------------------------- the CLI checks outputs before the work
COMMANDS = {  # command line with {out}, the function doing the work, the suffix it wants
    "show": (["show", "a", "--out", "{out}"], "gdnplan.cli.plan.scene_and_start", ".png"),
    "field": (["field", "--out", "{out}"], "gdnplan.evaluate.fig5", ".png"),
    "plan": (
        ["plan", "problems/planar2_square.toml", "--animate", "{out}"],
        "gdnplan.trajopt.plan",
        ".gif",
    ),
    "fetch": (["fetch", "--animate", "{out}"], "gdnplan.fetch.run_fetch", ".gif"),
    "table1": (["reproduce", "table1", "--out", "{out}"], "gdnplan.evaluate.table1", ".md"),
    "table2": (
        ["reproduce", "table2", "--out", "{out}"],
        "gdnplan.table2.reaching_problems",
        ".md",
    ),
    "train": (["train", "--env", "a", "--out", "{out}"], "gdnplan.train.train", ".safetensors"),
}


def bad_outputs(tmp_path, suffix):
    """One path of every class of unwritable output for a file with ``suffix``."""
    file = tmp_path / "file"
    file.write_text("")
    (tmp_path / f"dir{suffix}").mkdir()
    (tmp_path / f"link{suffix}").symlink_to(file)
    os.mkfifo(tmp_path / f"fifo{suffix}")
    bad = {
        "no suffix": tmp_path / "out",
        "directory": tmp_path / f"dir{suffix}",
        "symlink": tmp_path / f"link{suffix}",
        "FIFO": tmp_path / f"fifo{suffix}",
        "parent is a file": file / f"a{suffix}",
        "read-only place": f"/proc/a{suffix}",
        "device without suffix": "/dev/full",
    }
    if os.geteuid() == 0:  # a character device (/dev/full's numbers) under a good name
        os.mknod(tmp_path / f"full{suffix}", stat.S_IFCHR | 0o666, os.makedev(1, 7))
        bad["device"] = tmp_path / f"full{suffix}"
    return bad


@pytest.mark.parametrize("command", sorted(COMMANDS))
def test_bad_output_paths_fail_before_the_work(command, tmp_path, monkeypatch, capsys):
    import importlib

    from gdnplan.cli import run

    args, work, suffix = COMMANDS[command]
    module, name = work.rsplit(".", 1)

    def started(*a, **k):
        raise AssertionError(f"{work} ran before the output path was checked")

    monkeypatch.setattr(importlib.import_module(module), name, started)
    monkeypatch.chdir(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    for kind, out in bad_outputs(tmp_path, suffix).items():
        before = sorted(p.name for p in tmp_path.iterdir())
        with pytest.raises(SystemExit) as exit_:
            run([a.replace("{out}", str(out)) for a in args])
        err = capsys.readouterr().err
        assert exit_.value.code == 2 and err.startswith("error: --"), (kind, err)
        assert err.count("\n") == 1 and str(out) in err, (kind, err)
        assert sorted(p.name for p in tmp_path.iterdir()) == before, kind
    for path in tmp_path.iterdir():  # nothing was replaced
        assert path.name == "file" or not path.is_file() or path.is_symlink(), path


def test_generate_refuses_a_data_root_that_is_a_file(tmp_path, monkeypatch, capsys):
    import gdnplan.data
    from gdnplan.cli import run

    monkeypatch.setattr(gdnplan.data, "generate", lambda *a: pytest.fail("work started"))
    (tmp_path / "root").write_text("")
    with pytest.raises(SystemExit) as exit_:
        run(["generate", "--env", "a", "--n", "5", "--data", str(tmp_path / "root")])
    assert exit_.value.code == 2 and "error: --data" in capsys.readouterr().err


def enospc_after_a_part(real):
    """A writer that writes a part of its output through ``real``, then hits a full disk."""

    def writer(*args, **kwargs):
        real(*args, **kwargs)
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    return writer


def test_the_package_writers_leave_no_temp_on_a_full_disk(tmp_path, monkeypatch):
    """savefig (PNG, GIF frames), safetensors and JSON writers failing midway: no temp left,
    the previous file kept, one OutputError naming the path."""
    import torch
    from matplotlib.figure import Figure

    import gdnplan.models.weights as w
    from gdnplan.viz import save_figure

    png = tmp_path / "a.png"
    png.write_bytes(b"old png")
    monkeypatch.setattr(Figure, "savefig", enospc_after_a_part(Figure.savefig))
    with pytest.raises(OutputError, match=re.escape(str(png)) + ".*No space left"):
        save_figure(Figure(), png)
    monkeypatch.undo()
    pair = w.write_weights(tmp_path / "n.safetensors", {"x": torch.zeros(2)}, {"v": 1})
    before = pair.read_bytes(), w.card_path(pair).read_bytes()
    monkeypatch.setattr(w, "save_file", enospc_after_a_part(w.save_file))
    with pytest.raises(OutputError, match="No space left"):
        w.write_weights(pair, {"x": torch.ones(2)}, {"v": 2})
    assert (pair.read_bytes(), w.card_path(pair).read_bytes()) == before
    assert png.read_bytes() == b"old png" and leftovers(tmp_path) == []


@pytest.mark.filterwarnings("ignore:Animation was deleted")  # the fake writer renders nothing
@pytest.mark.parametrize("failure", ["enospc", "interrupt"])
def test_an_animation_failing_midway_leaves_no_temp_gif(tmp_path, monkeypatch, failure):
    from matplotlib.animation import Animation

    import gdnplan as gp
    from gdnplan.viz import animate_paths

    real = Animation.save

    def broken(self, filename, *args, **kwargs):
        with open(filename, "wb") as f:
            f.write(b"GIF89a" + b"\0" * 65536)  # the first frames
        if failure == "interrupt":
            raise KeyboardInterrupt
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(Animation, "save", broken)
    q = np.array([[0.0, 0.0], [0.1, 0.1]])
    with pytest.raises(KeyboardInterrupt if failure == "interrupt" else OutputError):
        animate_paths([(gp.make_scene("a"), q)], tmp_path / "a.gif", per_segment=1)
    assert list(tmp_path.iterdir()) == []
    monkeypatch.setattr(Animation, "save", real)
    animate_paths([(gp.make_scene("a"), q)], tmp_path / "a.gif", per_segment=1)
    assert (tmp_path / "a.gif").read_bytes()[:6] == b"GIF89a" and leftovers(tmp_path) == []
