import json
import subprocess
import sys

import numpy as np
import pytest
from typer.testing import CliRunner

import gdnplan as gp
from gdnplan.cli import app

runner = CliRunner()


def test_show_writes_png(tmp_path):
    out = tmp_path / "scene.png"
    result = runner.invoke(
        app, ["show", "d", "--seed", "3", "--q", "0.3,0.2,0.1,0.5,-0.4,0.6,0.2", "--out", str(out)]
    )
    assert result.exit_code == 0, result.output
    assert out.read_bytes()[:4] == b"\x89PNG"


def test_show_from_problem_file(tmp_path):
    problem = tmp_path / "p.toml"
    problem.write_text(
        '[robot]\nname = "planar2"\n'
        "[[obstacles]]\npolygon = [[0.5, 0.5], [0.8, 0.5], [0.8, 0.8]]\n"
        "[start]\nq = [0.0, 0.1]\n"
    )
    out = tmp_path / "p.png"
    result = runner.invoke(app, ["show", str(problem), "--out", str(out)])
    assert result.exit_code == 0, result.output
    assert out.exists()


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["show", "zz"], "scene: unknown name"),
        (["show", "d", "--q", "1,2"], "--q: expected shape"),
        (["show", "d", "--q", "1,x"], "--q: expected numbers"),
        (["show", "missing.toml"], "no such file"),
    ],
)
def test_bad_input_prints_one_line_and_exits_2(args, message):
    proc = subprocess.run(
        [sys.executable, "-c", "from gdnplan.cli import main; main()", *args],
        capture_output=True,
        text=True,
    )
    assert proc.returncode == 2
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: ") and message in lines[0], proc.stderr


def test_malformed_toml_names_the_file(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text("[robot\nname = 1")
    proc = subprocess.run(
        [sys.executable, "-c", "from gdnplan.cli import main; main()", "show", str(bad)],
        capture_output=True,
        text=True,
    )
    assert proc.returncode == 2 and "malformed TOML" in proc.stderr


def test_generate_then_train_writes_loadable_weights(tmp_path):
    """The data → training path as a user runs it: two CLI commands, then gp.load_model."""
    data = tmp_path / "data"
    for split, n in (("train", 80), ("test", 40)):
        result = runner.invoke(
            app,
            [
                "generate",
                "--env",
                "a",
                "--split",
                split,
                "--n",
                str(n),
                "--data",
                str(data),
                "--workers",
                "1",
            ],
        )
        assert result.exit_code == 0, result.output
    out = tmp_path / "a.safetensors"
    result = runner.invoke(
        app,
        [
            "train",
            "--env",
            "a",
            "--data",
            str(data),
            "--out",
            str(out),
            "--epochs",
            "1",
            "--set",
            "layers=1",
            "--run-dir",
            str(tmp_path / "run"),
        ],
    )
    assert result.exit_code == 0, result.output
    card = json.loads(out.with_suffix(".json").read_text())
    assert card["config"]["layers"] == 1 and card["test"]["n"] == 40
    model = gp.load_model(out)
    scene = gp.make_scene("a")
    d = model.distance(scene, scene.robot.sample(5, seed=0))
    assert d.shape == (5,) and np.isfinite(d).all()

    # fine-tune from those weights with extra near-boundary samples: zero learning rate keeps
    # them, the card records the start and the extra data
    near = tmp_path / "near"
    args = ["generate", "--env", "a", "--seed", "5", "--near", "1", "--n", "30", "--data",
            str(near), "--workers", "1"]  # fmt: skip
    assert runner.invoke(app, args).exit_code == 0
    tuned = tmp_path / "a_tuned.safetensors"
    args = ["train", "--env", "a", "--data", str(data), "--out", str(tuned), "--epochs", "1",
            "--lr", "0", "--init", str(out), "--run-dir", str(tmp_path / "run2"),
            "--extra", str(near / "a" / "train")]  # fmt: skip
    result = runner.invoke(app, args)
    assert result.exit_code == 0, result.output
    card = json.loads(tuned.with_suffix(".json").read_text())
    assert card["config"]["layers"] == 1 and card["init"]["path"] == str(out)
    assert card["data"]["extra"] == {str(near / "a" / "train"): 30}
    assert card["data"]["n_train"] == 72 + 30
    np.testing.assert_allclose(
        gp.load_model(tuned).distance(scene, scene.robot.sample(5, seed=0)), d
    )


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["train", "--env", "a", "--model", "svm"], "--model: expected"),
        (["train", "--env", "a", "--preset", "fast"], "--preset: expected"),
        (["generate", "--env", "a", "--split", "val"], "--split: expected"),
        (["train", "--env", "a", "--init", "missing.safetensors"], "--init: no card"),
        (["train", "--env", "a", "--compile", "--set", "grad_weight=0.1"], "double backward"),
    ],
)
def test_train_and_generate_reject_bad_options(args, message):
    result = runner.invoke(app, args)
    assert result.exit_code != 0
    assert message in str(result.exception) or message in result.output


def test_plan_rejects_zero_threads():
    result = runner.invoke(app, ["plan", "problems/planar2_square.toml", "--threads", "0"])
    assert result.exit_code != 0
    assert "--threads" in str(result.exception) + result.output
