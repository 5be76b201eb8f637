import json
import subprocess
import sys
from pathlib import Path

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
        (["show", "missing.toml"], "No such file"),
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
        (
            ["train", "--env", "a", "--init", "missing.safetensors"],
            "--init: missing.safetensors does not exist",
        ),
        (["train", "--env", "a", "--compile", "--set", "grad_weight=0.1"], "double backward"),
        # audit: 3-D weights were "--set: unknown GraphDistNet options ['length', 'rim']"
        (["train", "--env", "a", "--init", "ur5e_storage3d"], "holds 'graphdistnet3d' weights"),
        (["train", "--env", "a", "--init", "clearancenet_b"], "holds 'clearancenet' weights"),
    ],
)
def test_train_and_generate_reject_bad_options(args, message):
    result = runner.invoke(app, args)
    assert result.exit_code != 0
    assert message in str(result.exception) or message in result.output


@pytest.mark.parametrize(("value", "message"), [(float("nan"), "NaN or infinite"), (1e30, "1e+06")])
def test_train_refuses_init_weights_that_cannot_train(tmp_path, value, message):
    """Audit: --init weights of NaN or huge values trained an epoch and were reported as a
    run that "diverged at epoch 0: lower the learning rate"."""
    from safetensors.torch import load_file

    from gdnplan.assets import weights_file
    from gdnplan.models.weights import read_card, write_weights

    src = weights_file("a")
    tensors = load_file(str(src))
    tensors[next(iter(tensors))].view(-1)[0] = value
    path = write_weights(tmp_path / "bad.safetensors", tensors, read_card(src))
    result = runner.invoke(app, ["train", "--env", "a", "--init", str(path)])
    assert result.exit_code != 0
    assert message in str(result.exception) and "bad.safetensors" in str(result.exception)


def test_plan_rejects_zero_threads():
    result = runner.invoke(app, ["plan", "problems/planar2_square.toml", "--threads", "0"])
    assert result.exit_code != 0
    assert "--threads" in str(result.exception) + result.output


# ---------------------------------------------------------------- hostile invocations (issue 19)
ROOT = __import__("pathlib").Path(__file__).resolve().parent.parent
SQUARE = str(ROOT / "problems" / "planar2_square.toml")
HOSTILE_FILES = {  # name -> bytes of a problem file show/plan must reject in one line
    "top_level_start.toml": b'start = [0.0, 0.1]\n[robot]\nname = "planar2"\n',
    "ragged.toml": b'[robot]\nname = "planar2"\n[start]\nq = [[0.0], [0.1, 0.2]]\n',
    "short.toml": b'[robot]\nname = "planar2"\n[start]\nq = [0.0]\n',
    "binary.toml": b"\xff\xfe\x00[robot]\n",
    "deep.toml": b"x = " + b"[" * 5000 + b"]" * 5000 + b"\n",
    "out_of_limits.toml": b'[robot]\nname = "planar2"\n[start]\nq = [9.0, 0.1]\n',
    "bad_goal.toml": b'[robot]\nname = "planar2"\n[start]\nq = [0.0, 0.1]\n[goal]\nq = [1, 2, 3]\n',
}
HOSTILE = [
    ["show", "d", "--seed", "-1"],
    ["show", "d", "--q", "9,0,0,0,0,0,0"],
    ["show", "d", "--q", "nan,0,0,0,0,0,0"],
    ["show", "{tmp}/dir.toml"],
    *(["show", f"{{tmp}}/{name}"] for name in HOSTILE_FILES),
    ["plan", "{tmp}/ragged.toml"],
    ["plan", SQUARE, "--seed", "-1"],
    ["plan", SQUARE, "--weights", str(ROOT / "weights" / "d.safetensors")],  # planar7 weights
    ["plan", SQUARE, "--weights", "{tmp}/empty.safetensors"],
    ["plan", SQUARE, "--bogus"],
    ["plan"],
    ["fetch", "--seed", "-1"],
    ["generate", "--env", "a", "--seed", "-1"],
    ["generate", "--env", "a", "--n", "0"],
    ["generate", "--env", "a", "--n", "5", "--near", "2"],
    ["generate", "--env", "a", "--workers", "0"],
    ["reproduce", "table2", "--first", "-5"],
    ["reproduce", "table2", "--n", "2", "--first", "5"],
    ["field", "--grid", "0"],
    ["field", "--grid", "1"],
    ["field", "--grid", "-3"],
    ["field", "--grid", "100000"],
    ["field", "--env", "d"],
    ["evaluate", "--n", "0"],
    ["evaluate", "--n-grad", "0"],
    ["evaluate", "--env", "zz"],
    *(
        ["train", "--env", "a", *option]
        for option in (
            ["--batch", "0"],
            ["--batch", "-5"],
            ["--lr", "nan"],
            ["--lr", "-1"],
            ["--lr", "inf"],
            ["--device", "tpu"],
            ["--device", "cuda:7"],
            ["--n-train", "0"],
            ["--n-train", "1"],
            ["--epochs", "-1"],
            ["--epochs", "0"],
            ["--patience", "0"],
            ["--time-budget", "-1"],
            ["--time-budget", "nan"],
            ["--set", "layers"],
            ["--set", 'layers="x"'],
            ["--set", "hidden=-4"],
            ["--set", "nope=1"],
            ["--model", "clearancenet", "--time-budget", "-1"],
        )
    ),
]


@pytest.fixture
def hostile_dir(tmp_path, monkeypatch):
    """A working directory with the hostile inputs; outputs default into it."""
    for name, content in HOSTILE_FILES.items():
        (tmp_path / name).write_bytes(content)
    (tmp_path / "dir.toml").mkdir()
    (tmp_path / "empty.safetensors").write_bytes(b"")
    (tmp_path / "empty.json").write_text('{"model": "graphdistnet"}')
    monkeypatch.chdir(tmp_path)
    return tmp_path


@pytest.mark.parametrize("args", HOSTILE, ids=lambda a: " ".join(a)[-60:])
def test_hostile_invocation_is_one_error_line_exit_2_and_writes_nothing(args, hostile_dir, capsys):
    from gdnplan.cli import run

    before = sorted(hostile_dir.rglob("*"))
    args = [a.replace("{tmp}", str(hostile_dir)) for a in args]
    with pytest.raises(SystemExit) as exit_:
        run([*args, *(["--data", str(hostile_dir / "data")] if args[0] == "generate" else [])])
    err = capsys.readouterr().err
    lines = err.strip().splitlines()
    assert exit_.value.code == 2, err
    assert len(lines) == 1 and lines[0].startswith("error: "), err
    assert "Traceback" not in err
    assert sorted(hostile_dir.rglob("*")) == before  # nothing written


def _cli(code: str, *args: str) -> subprocess.CompletedProcess:
    """Run ``main()`` in a subprocess after ``code`` (e.g. a monkeypatch of a failure)."""
    script = f"import gdnplan.cli as cli\n{code}\ncli.main()"
    return subprocess.run([sys.executable, "-c", script, *args], capture_output=True, text=True)


BOOM = "def boom(*a, **k):\n    raise {}\nimport gdnplan.scene\ngdnplan.scene.make_scene = boom"


def test_unexpected_exception_is_one_line_exit_3_and_debug_shows_the_traceback():
    proc = _cli(BOOM.format("ZeroDivisionError('x\\ny')"), "show", "d")
    assert proc.returncode == 3 and "Traceback" not in proc.stderr
    assert proc.stderr.splitlines() == [
        "error: internal error (ZeroDivisionError: x y); rerun with --debug for the traceback"
    ]
    proc = _cli(BOOM.format("ZeroDivisionError('x')"), "--debug", "show", "d")
    assert proc.returncode == 3 and "Traceback" in proc.stderr and "in boom" in proc.stderr
    assert proc.stderr.splitlines()[-1].startswith("error: internal error (ZeroDivisionError")


@pytest.mark.skipif(not Path("/dev/full").exists(), reason="needs /dev/full")
@pytest.mark.parametrize(
    "args", [["--help"], ["--version"], ["plan", "--help"]], ids=lambda a: " ".join(a)
)
def test_a_full_standard_output_is_one_line_exit_2(args):
    """`gdnplan … > /dev/full` was exit 3, an internal error (OSError: No space left)."""
    with open("/dev/full", "w") as full:
        proc = subprocess.run(
            [sys.executable, "-m", "gdnplan", *args], stdout=full, stderr=subprocess.PIPE, text=True
        )
    assert proc.returncode == 2, proc.stderr
    assert proc.stderr.splitlines() == [
        "error: standard output: cannot write (No space left on device); redirect it"
    ]


def test_an_os_error_elsewhere_stays_an_internal_error():
    proc = _cli(BOOM.format("OSError(28, 'No space left on device')"), "show", "d")
    assert proc.returncode == 3 and proc.stderr.startswith("error: internal error (OSError")


def test_interrupt_is_one_line_exit_130():
    proc = _cli(BOOM.format("KeyboardInterrupt"), "show", "d")
    assert proc.returncode == 130 and proc.stderr.splitlines() == ["error: interrupted"]


def test_input_errors_stay_exit_2_and_usage_errors_are_one_line():
    proc = _cli("", "field", "--grid", "x")
    assert proc.returncode == 2 and len(proc.stderr.splitlines()) == 1
    assert proc.stderr.startswith("error: Invalid value for '--grid'")
    proc = _cli("", "--debug", "show", "zz")
    assert proc.returncode == 2 and "Traceback" in proc.stderr
    assert proc.stderr.splitlines()[-1].startswith("error: scene: unknown name")


# ---------------------------------------------------------------- train: every flag × model
# flag -> (arguments, the value the run must receive: f(kind, captured call) -> value, expected)
TRAIN_FLAGS = {
    "--n-train": (["--n-train", "50"], lambda k, c: c["n_train"], 50),
    "--batch": (["--batch", "8"], lambda k, c: c["fit"].batch, 8),
    "--lr": (["--lr", "0.01"], lambda k, c: c["fit"].lr, 0.01),
    "--epochs": (["--epochs", "3"], lambda k, c: c["fit"].epochs, 3),
    "--patience": (["--patience", "2"], lambda k, c: c["fit"].patience, 2),
    "--time-budget": (["--time-budget", "5"], lambda k, c: c["fit"].time_budget, 5.0),
    "--seed": (["--seed", "4"], lambda k, c: c["fit"].seed, 4),
    "--device": (["--device", "cpu"], lambda k, c: c["fit"].device, "cpu"),
    "--threads": (["--threads", "2"], lambda k, c: c["threads"], 2),
    "--data": (["--data", "elsewhere"], lambda k, c: str(c["root"]), "elsewhere"),
    "--out": (["--out", "{tmp}/w.safetensors"], lambda k, c: c["out"].name, "w.safetensors"),
    "--preset": (["--preset", "faithful"], lambda k, c: c["config"].network.cross, "argmax"),
    "--name": (["--name", "run7"], lambda k, c: c["name"], "run7"),
    "--set": (["--set", "layers=2"], lambda k, c: c["config"].network.layers, 2),
    "--run-dir": (["--run-dir", "{tmp}/r"], lambda k, c: c["run_dir"].name, "r"),
    "--compile": (["--compile"], lambda k, c: c["config"].compile, True),
    "--init": (["--init", "b"], lambda k, c: c["config"].init.name, "b.safetensors"),
    "--extra": (["--extra", "more"], lambda k, c: c["config"].extra, (Path("more"),)),
}
GRAPHDISTNET_ONLY = {"--preset", "--name", "--set", "--run-dir", "--compile", "--init", "--extra"}


@pytest.fixture
def captured_training(monkeypatch, tmp_path):
    """Replace both trainers by recorders of what the command gives them (nothing trains);
    run from an empty folder (the default weights/<env> is then no shipped file)."""
    import torch

    import gdnplan.train

    calls: dict = {}
    threads = torch.get_num_threads()

    def graphdistnet(env, config, name, data_root, out, run_dir):
        calls.update(kind="graphdistnet", config=config, fit=config.fit, name=name,
                     n_train=config.n_train, root=data_root, out=out, run_dir=run_dir,
                     threads=torch.get_num_threads())  # fmt: skip
        return {"name": name, "test": {}}

    def clearancenet(env, fit, out, n_train, root, command):
        calls.update(kind="clearancenet", fit=fit, out=out, n_train=n_train, root=root,
                     threads=torch.get_num_threads())  # fmt: skip
        return {"test": {}}

    monkeypatch.setattr(gdnplan.train, "train", graphdistnet)
    monkeypatch.setattr(gdnplan.train, "train_and_score", clearancenet)
    monkeypatch.chdir(tmp_path)
    yield calls
    torch.set_num_threads(threads)


@pytest.mark.parametrize("model", ["graphdistnet", "clearancenet"])
@pytest.mark.parametrize("flag", sorted(TRAIN_FLAGS))
def test_every_train_flag_applies_to_the_model_or_is_refused(
    flag, model, captured_training, tmp_path, capsys
):
    """No option is ignored: it reaches the run of every model it applies to, and with a model
    it does not apply to the command fails with one line naming the option and the model."""
    from gdnplan.cli import run

    args, received, expected = TRAIN_FLAGS[flag]
    args = [a.replace("{tmp}", str(tmp_path)) for a in args]
    with pytest.raises(SystemExit) as exit_:
        run(["train", "--env", "a", "--model", model, *args])
    err = capsys.readouterr().err
    if model == "clearancenet" and flag in GRAPHDISTNET_ONLY:
        assert exit_.value.code == 2 and err.count("\n") == 1, err
        assert err.startswith(f"error: {flag}: does not apply to --model clearancenet"), err
        assert not captured_training
        return
    assert exit_.value.code == 0, err
    assert captured_training["kind"] == model
    assert received(model, captured_training) == expected


def test_clearancenet_keeps_its_default_budget_and_preset_with_init_is_refused(
    captured_training, capsys
):
    from gdnplan.cli import run

    with pytest.raises(SystemExit):
        run(["train", "--env", "a", "--model", "clearancenet"])
    assert captured_training["fit"].time_budget == 120.0
    with pytest.raises(SystemExit) as exit_:
        run(["train", "--env", "a", "--preset", "smooth", "--init", "a"])
    assert (
        exit_.value.code == 2 and "--preset: does not apply with --init" in capsys.readouterr().err
    )


def test_an_old_solver_table_warns_its_author_in_one_line_and_still_plans(tmp_path):
    problem = tmp_path / "old.toml"
    problem.write_text(
        '[robot]\nname = "planar2"\n[scene]\ngenerator = "b"\nseed = 1\n'
        "[start]\nq = [0.0, 0.0]\n[goal]\nq = [1.0, 1.0]\n[solver]\nrrt_time = 1.0\n"
    )
    proc = _cli("", "plan", str(problem), "--collision", "coal", "--json", "-q")
    warning = "warning: problem file: the [solver] table is deprecated; move its keys: "
    assert proc.returncode == 0, proc.stderr
    assert proc.stderr.splitlines() == [warning + "rrt_time → [seed] rrt_time"]
    assert json.loads(proc.stdout)["success"] is True  # stdout stays one JSON object


def test_fetch_stage_lines_state_what_each_certificate_proves():
    """A planned stage: its proven clearance; the lift (certified from its second waypoint):
    the bound from there and the distance before it, not a bound it does not prove."""
    from types import SimpleNamespace

    from gdnplan.cli.plan import stage_clearance

    planned = SimpleNamespace(certified_from=0, min_distance=0.0123, certified_min_distance=None)
    assert stage_clearance(planned) == "certified clearance ≥ +0.0123 m"
    lift = SimpleNamespace(certified_from=1, min_distance=0.0, certified_min_distance=0.00171)
    text = stage_clearance(lift)
    assert text.startswith("certified clearance ≥ +0.0017 m from waypoint 1 on")
    assert "+0.0000 m before it" in text


def test_a_plan_without_obstacles_says_so_not_that_its_clearance_is_unproven(tmp_path):
    # min_distance is +inf when there is nothing to collide with; the text said "clearance not
    # proven" beside "certified collision-free" (−inf is the bound of a failed certificate)
    from gdnplan.cli.plan import clearance_text

    problem = tmp_path / "free.toml"
    problem.write_text(
        '[robot]\nname = "planar2"\n\n[start]\nq = [0.5, 0.5]\n\n[goal]\nq = [1.5, 0.5]\n'
    )
    result = CliRunner().invoke(app, ["plan", str(problem), "--collision", "coal", "-q"])
    assert result.exit_code == 0, result.output
    assert "certified collision-free; nothing to collide with (no obstacles)" in result.output
    assert clearance_text(float("-inf")) == clearance_text(float("nan")) == "clearance not proven"
    assert clearance_text(0.0123) == "certified clearance ≥ +0.0123 m"


def test_plan_prints_the_certified_clearance_rounded_down(tmp_path):
    # a held-out problem (scene (b), seed 7002) whose proven bound is 0.7263805 m: the line said
    # "certified clearance ≥ +0.7264 m", 0.02 mm more than the certificate proved
    problem = tmp_path / "b7002.toml"
    problem.write_text(
        '[robot]\nname = "planar2"\n\n[scene]\ngenerator = "b"\nseed = 7002\n\n'
        "[start]\nq = [1.4902181457246444, 1.2165196008289119]\n\n"
        "[goal]\nq = [2.0507360222777917, 2.1978629242595566]\n\n"
        "[options]\nwaypoints = 20\nmargin = 0.02\n"
    )
    args = ["plan", str(problem), "--collision", "coal", "-q"]
    text = CliRunner().invoke(app, args)
    summary = json.loads(CliRunner().invoke(app, [*args, "--json"]).output)
    assert text.exit_code == 0 and summary["success"], text.output
    printed = float(text.output.split("certified clearance ≥ ")[1].split(" m")[0])
    assert printed <= summary["min_distance"] < printed + 1e-4


@pytest.mark.parametrize("model", ["graphdistnet", "clearancenet"])
def test_training_never_replaces_shipped_weights_unless_asked(
    model, captured_training, tmp_path, capsys
):
    """From the repository root weights/ is the shipped folder: a bare `gdnplan train` (or an
    --out into it) would silently replace what every plan by that name uses."""
    from gdnplan.assets import WEIGHTS_DIR
    from gdnplan.cli import run

    (tmp_path / "weights").symlink_to(WEIGHTS_DIR)  # as in the repository root
    name = "clearancenet_a" if model == "clearancenet" else "a"
    for args in ([], ["--out", str(WEIGHTS_DIR / f"{name}.safetensors")]):
        with pytest.raises(SystemExit) as exit_:
            run(["train", "--env", "a", "--model", model, *args])
        err = capsys.readouterr().err
        assert exit_.value.code == 2 and "is a shipped weights file" in err, err
        assert "--replace-shipped" in err and not captured_training
    with pytest.raises(SystemExit) as exit_:
        run(["train", "--env", "a", "--model", model, "--replace-shipped"])
    assert exit_.value.code == 0 and captured_training["kind"] == model


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["reproduce", "table1", "--fast", "--envs", "aa"], "--envs: 'a' is given twice"),
        (["reproduce", "ablation", "--fast", "--envs", "b,b"], "--envs: 'b' is given twice"),
        (["reproduce", "table1", "--fast", "--weights", "/nonexistent"], "--weights: /nonexistent"),
        (["evaluate", "--env", "a", "--model", "coal", "--n", "5", "--n-grad", "6"], "--n-grad: 6"),
    ],
)
def test_reproduce_and_evaluate_refuse_repeats_missing_weights_and_too_many_grad_samples(
    args, message, tmp_path, capsys
):
    from gdnplan.cli import run

    with pytest.raises(SystemExit) as exit_:
        run([*args, *(["--out", str(tmp_path / "t.md")] if "reproduce" in args else [])])
    assert exit_.value.code == 2 and message in capsys.readouterr().err


def test_evaluate_prints_na_not_nan_for_an_undefined_auc(capsys):
    from gdnplan.cli import run

    with pytest.raises(SystemExit) as exit_:
        run(["evaluate", "--env", "a", "--model", "coal", "--n", "1", "--n-grad", "1"])
    out = capsys.readouterr().out
    assert exit_.value.code == 0 and "nan" not in out.lower(), out
    assert "AUC N/A (one class among 1 samples)" in out and "± N/A (one sample)" in out


def test_reproduce_faithful_replaces_shipped_weights_only_when_asked(capsys, tmp_path):
    """Its default --out is the shipped <env>_faithful file (its reproduction command)."""
    from gdnplan.cli import run

    with pytest.raises(SystemExit) as exit_:
        run(["reproduce", "faithful", "--env", "d", "--data", str(tmp_path)])
    err = capsys.readouterr().err
    assert exit_.value.code == 2 and "d_faithful" in err and "--replace-shipped" in err, err
