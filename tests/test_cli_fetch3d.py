"""``gdnplan fetch --3d``: bad input is one error line with exit 2 and nothing written; the
whole fetch (slow) prints every stage certified and writes a problem file per planned stage."""

from __future__ import annotations

import json

import pytest

from gdnplan.arm3d.fetch3d import PLANNED, STAGES
from gdnplan.trajopt import Problem

BAD = [
    ["fetch", "--3d", "--seed", "abc"],
    ["fetch", "--3d", "--seed", "1.5"],
    ["fetch", "--3d", "--seed", "-1"],
    ["fetch", "--3d", "--placement", "0.7,0,3.14159"],  # the entrance faces away: out of reach
    ["fetch", "--3d", "--placement", "0.7,0"],
    ["fetch", "--3d", "--placement", "0.7,x,0"],
    ["fetch", "--3d", "--placement", "1.0,0,0"],  # off the table
    ["fetch", "--3d", "--placement", "nan,0,0"],
    ["fetch", "--placement", "0.7,0,0"],  # planar fetch
    ["fetch", "--write-problems", "{tmp}/out"],
    ["fetch", "--3d", "--animate", "{tmp}/x.gif"],
    ["fetch", "--3d", "--collision", "graphdistnet3d"],
    ["fetch", "--3d", "--collision", "graphdistnet"],  # was silently coal
    ["fetch", "--3d", "--collision", "graphdistnet", "--weights", "ur5e_boxes3d_preliminary"],
    ["fetch", "--3d", "--weights", "ur5e_boxes3d_preliminary"],  # weights without graphdistnet
    ["fetch", "--3d", "--write-problems", "{tmp}/a_file"],
    ["fetch", "--3d", "--view3d"],
    ["fetch", "--3d", "--write-problems", ""],  # wrote into the working directory
    ["fetch", "--3d", "--write-problems", "{tmp}/" + "x" * 300],  # exit 3: ENAMETOOLONG
    ["fetch", "--3d", "--collision", ""],  # was silently coal
    ["fetch", "--collision", ""],  # was silently graphdistnet
]


@pytest.mark.parametrize("args", BAD, ids=lambda a: " ".join(a[1:]))
def test_bad_input_is_one_error_line_exit_2_and_writes_nothing(args, tmp_path, capsys):
    from gdnplan.cli import run

    (tmp_path / "a_file").write_text("x")
    before = sorted(tmp_path.rglob("*"))
    with pytest.raises(SystemExit) as exit_:
        run([a.replace("{tmp}", str(tmp_path)) for a in args])
    err = capsys.readouterr().err
    lines = err.strip().splitlines()
    assert exit_.value.code == 2, err
    assert len(lines) == 1 and lines[0].startswith("error: "), err
    assert sorted(tmp_path.rglob("*")) == before


@pytest.mark.slow
def test_the_canonical_3d_fetch_is_certified_and_writes_its_problems(tmp_path, capsys):
    from gdnplan.cli import run

    out = tmp_path / "problems"
    with pytest.raises(SystemExit) as exit_:
        run(["fetch", "--3d", "--json", "-q", "--write-problems", str(out)])
    assert exit_.value.code in (0, None)
    summary = json.loads(capsys.readouterr().out)
    assert summary["success"] and [s["stage"] for s in summary["stages"]] == list(STAGES)
    assert all(s["success"] for s in summary["stages"])
    assert sorted(p.name for p in out.iterdir()) == sorted(f"fetch3d_{s}.toml" for s in PLANNED)
    for path in out.iterdir():
        assert Problem.from_toml(path).scene.robot.name == "ur5e"


def test_the_shipped_fetch_weights_are_taken_by_name():
    """``--weights ur5e_storage3d``: the shipped GraphDistNet-3D weights of the 3-D fetch load
    by name and know both fetch scenes (fingers open, holding the stick)."""
    from gdnplan.arm3d.fetch3d_scene import fetch3d
    from gdnplan.cli.fetch3d import learned_fetch_model
    from gdnplan.errors import InputError
    from gdnplan.models import load_model

    model = learned_fetch_model("ur5e_storage3d")
    assert model.card["env"] == "ur5e_storage" and model.card["test"]["auc"] >= 0.99
    fetch = fetch3d(1)
    boxes = load_model("ur5e_boxes3d_preliminary")
    for scene in fetch.scenes.values():
        model.check_scene(scene)  # refuses (InputError) scenes unlike its training
        with pytest.raises(InputError):
            boxes.check_scene(scene)  # the random-boxes weights do not know the storage


@pytest.mark.slow
def test_the_3d_fetch_with_learned_constraints_is_certified(capsys):
    from gdnplan.cli import run

    args = ["fetch", "--3d", "--seed", "2", "--collision", "graphdistnet", "--weights",
            "ur5e_storage3d", "--json", "-q"]  # fmt: skip
    with pytest.raises(SystemExit) as exit_:
        run(args)
    assert exit_.value.code in (0, None)
    summary = json.loads(capsys.readouterr().out)
    assert summary["success"] and all(s["success"] for s in summary["stages"])


@pytest.mark.parametrize("text", ["0.6,,0", "0.6,0.2,", ",0.6,0.2,0", "0.6, ,0.2"])
def test_a_placement_with_an_empty_field_is_refused_not_shortened(text):
    from gdnplan.cli.fetch3d import parse_placement
    from gdnplan.errors import InputError

    with pytest.raises(InputError, match="--placement: an empty field"):
        parse_placement(text)


def test_a_placement_yaw_is_wrapped_exactly():
    import math

    from gdnplan.cli.fetch3d import parse_placement

    assert parse_placement("0.6 0.1 0.3") == parse_placement("0.6, 0.1, 0.3")
    wrapped = parse_placement(f"0.6,0.1,{0.3 + 4 * math.pi!r}")
    assert abs(wrapped.yaw - 0.3) < 1e-12
    assert -math.pi <= parse_placement("0.6,0.1,1e10").yaw <= math.pi
