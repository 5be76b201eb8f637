"""Input files are regular files of bounded size (gdnplan.files.read_input): a FIFO, a device
(``/dev/zero``), a directory or a huge file named as a problem, URDF, SRDF, point or card file
is one InputError naming it, before anything blocks or fills the memory."""

from __future__ import annotations

import os
import subprocess
import sys
import threading
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from gdnplan.errors import GdnplanError, InputError, ProblemFileError
from gdnplan.files import MAX_INPUT_BYTES, read_input

ROOT = Path(__file__).parent.parent
ANSWER_TIMEOUT = 60.0  # s: a hang guard, not a performance bound


def non_regular(tmp_path: Path, kind: str) -> Path:
    """A FIFO, a symlink to /dev/zero, or a directory at ``tmp_path / kind``."""
    path = tmp_path / kind
    if kind == "fifo":
        os.mkfifo(path)
    elif kind == "zero":
        path.symlink_to("/dev/zero")
    else:
        path.mkdir()
    return path


def sparse(path: Path, size: int) -> Path:
    """A file of ``size`` bytes that takes no disk space."""
    with open(path, "wb") as f:
        f.truncate(size)
    return path


@given(data=st.binary(max_size=2000), limit=st.integers(0, 3000))
@settings(max_examples=60, deadline=None)
def test_read_input_returns_a_regular_files_bytes_up_to_the_limit(tmp_path_factory, data, limit):
    path = tmp_path_factory.mktemp("in") / "f.bin"
    path.write_bytes(data)
    if len(data) <= limit:
        assert read_input(path, "thing", limit) == data
    else:
        with pytest.raises(InputError, match=r"thing: .*f\.bin is larger than"):
            read_input(path, "thing", limit)


@pytest.mark.parametrize("kind", ["fifo", "zero", "folder"])
def test_read_input_refuses_what_is_not_a_regular_file_without_blocking(tmp_path, kind):
    path = non_regular(tmp_path, kind)
    caught: list[BaseException] = []

    def read() -> None:
        try:
            read_input(path, "thing")
        except BaseException as e:  # handed to the test thread
            caught.append(e)

    worker = threading.Thread(target=read, daemon=True)  # a blocked read would never return
    worker.start()
    worker.join(ANSWER_TIMEOUT)
    assert not worker.is_alive(), f"read_input blocked on a {kind}"
    assert len(caught) == 1 and isinstance(caught[0], InputError)
    assert f"thing: {path}" in str(caught[0])
    assert ("directory" if kind == "folder" else "not a regular file") in str(caught[0])


def test_read_input_names_a_missing_file(tmp_path):
    with pytest.raises(InputError, match=r"thing: cannot read .*nope.*No such file"):
        read_input(tmp_path / "nope", "thing")


def test_a_problem_file_larger_than_the_limit_is_refused_unread(tmp_path):
    from gdnplan.trajopt import read_problem_file

    path = sparse(tmp_path / "huge.toml", MAX_INPUT_BYTES + 1)
    with pytest.raises(ProblemFileError, match=r"huge\.toml is larger than"):
        read_problem_file(path)


@pytest.mark.parametrize("kind", ["fifo", "zero", "folder"])
def test_plan_and_show_refuse_a_non_regular_problem_file_in_one_line(tmp_path, kind):
    path = non_regular(tmp_path, kind)
    path = path.rename(tmp_path / f"{kind}.toml") if kind != "zero" else path
    if kind == "zero":
        path = tmp_path / "zero.toml"
        path.symlink_to("/dev/zero")
    for command in ("plan", "show"):
        run = subprocess.run(
            [sys.executable, "-m", "gdnplan.cli", command, str(path)],
            capture_output=True,
            text=True,
            timeout=ANSWER_TIMEOUT,
            cwd=tmp_path,
        )
        assert run.returncode == 2, run.stderr
        assert run.stderr.strip().splitlines() == [
            f"error: problem file: {path} is "
            + ("a directory; give a file" if kind == "folder" else
               "not a regular file (a device, FIFO or socket); give a file")
        ]  # fmt: skip


def cloud_problem(tmp_path: Path, file: str) -> Path:
    path = tmp_path / "cloud.toml"
    path.write_text(
        f'[robot]\nname = "ur5e"\n\n[[scene3d.obstacles]]\ntype = "cloud"\nfile = "{file}"\n\n'
        "[start]\nq = [0.0, -1.5, 1.5, 0.0, 0.5, 0.0]\n\n"
        "[goal]\nq = [1.0, -1.2, 1.2, 0.0, 0.5, 0.0]\n"
    )
    return path


@pytest.mark.parametrize("suffix", [".xyz", ".npy"])
def test_a_point_file_larger_than_the_limit_is_refused_unread(tmp_path, suffix):
    from gdnplan.trajopt import Problem

    sparse(tmp_path / f"big{suffix}", MAX_INPUT_BYTES + 1)
    with pytest.raises(ProblemFileError, match=f"point file: .*big\\{suffix} is larger than"):
        Problem.from_toml(cloud_problem(tmp_path, f"big{suffix}"))


def test_a_point_file_that_is_a_fifo_is_refused(tmp_path):
    from gdnplan.arm3d.cloud3d import read_cloud

    os.mkfifo(tmp_path / "scan.xyz")
    with pytest.raises(GdnplanError, match=r"scan\.xyz"):
        read_cloud(tmp_path / "scan.xyz")


def test_an_empty_point_file_is_refused_by_its_shape_without_a_numpy_warning(tmp_path):
    from gdnplan.arm3d.cloud3d import read_cloud

    (tmp_path / "scan.xyz").write_text("# only a comment\n")
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(InputError, match=r"got \(0, 1\)"):
            read_cloud(tmp_path / "scan.xyz")


def test_urdf_srdf_and_card_files_larger_than_the_limit_are_refused(tmp_path):
    from gdnplan.arm3d.pairs import srdf_disabled_pairs
    from gdnplan.models.checks import parse_card
    from gdnplan.urdf_robot import RobotSpec, robot_from_urdf

    big = sparse(tmp_path / "big.urdf", MAX_INPUT_BYTES + 1)
    with pytest.raises(InputError, match=r"urdf: .*big\.urdf is larger than"):
        robot_from_urdf("arm", RobotSpec(urdf=big, planning_joints=("a",)))
    with pytest.raises(InputError, match=r"srdf: .*big\.srdf is larger than"):
        srdf_disabled_pairs(sparse(tmp_path / "big.srdf", MAX_INPUT_BYTES + 1), model=None)
    with pytest.raises(InputError, match=r"weights: card: .*big\.json is larger than"):
        parse_card(sparse(tmp_path / "big.json", MAX_INPUT_BYTES + 1))


def test_a_mesh_file_larger_than_the_limit_is_refused_before_assimp_reads_it(tmp_path):
    import struct

    from gdnplan.arm3d.shapes import load_mesh

    path = tmp_path / "big.stl"  # a binary STL header claiming the triangles of a sparse file
    count = (MAX_INPUT_BYTES // 50) + 1
    path.write_bytes(b"\0" * 80 + struct.pack("<I", count))
    sparse(path, 84 + 50 * count)
    with pytest.raises(InputError, match=r"mesh file big\.stl: .*big\.stl is larger than"):
        load_mesh(path, name="m")
