"""The ablation (gdnplan.ablation): one change a step, resumable, and its --fast CLI run."""

import json
import time
from dataclasses import fields

import pytest
from typer.testing import CliRunner

import gdnplan.train as training
from gdnplan import ablation, data
from gdnplan.cli import app
from gdnplan.models.graphdistnet import GraphDistNetConfig


def test_each_step_changes_one_field_of_the_step_before():
    assert ablation.step_config(0) == GraphDistNetConfig.faithful()
    assert ablation.step_config(0).cross == "argmax" and ablation.step_config(0).two_way
    for step in range(1, len(ablation.STEPS)):
        before, after = ablation.step_config(step - 1), ablation.step_config(step)
        changed = [
            f.name for f in fields(after) if getattr(before, f.name) != getattr(after, f.name)
        ]
        assert changed == list(ablation.STEPS[step][2]), ablation.STEPS[step][0]


def test_every_ablated_option_is_what_some_shipped_network_uses():
    """Issue #25's rule for options: one whose step buys nothing is removed unless a shipped
    network needs it. Every step's changed value is set by at least one shipped card (the
    paper's argmax by the ``*_faithful`` ones), so each option stays; retraining the last
    user without it makes this fail and the option a candidate for removal."""
    from gdnplan.assets import WEIGHTS_DIR

    cards = [json.loads(p.read_text()) for p in WEIGHTS_DIR.glob("*.json")]
    configs = [
        GraphDistNetConfig.from_dict(c["config"]) for c in cards if c.get("model") == "graphdistnet"
    ]
    assert any(c.cross == "argmax" for c in configs)  # the faithful step's network
    for name, _, change in ablation.STEPS[1:]:
        users = [c for c in configs if all(getattr(c, k) == v for k, v in change.items())]
        assert users, f"step {name}: no shipped network uses {change}"


def test_faithful_run_has_the_shipped_weights_data_and_budget():
    c = ablation.faithful_config("a", "data")
    assert c.network == GraphDistNetConfig.faithful() and c.loss == training.GraphDistNetLoss()
    assert c.fit.time_budget == 2242 + 1560 + 1250 and c.extra == ("data/near/a/train",)
    assert ablation.faithful_config("e").n_train == 45_000
    assert ablation.faithful_config("d", budget=10).fit.time_budget == 10


@pytest.mark.slow  # seven trainings; the --fast CLI test below runs them in the default suite
def test_trained_steps_are_kept_and_skipped(tmp_path, monkeypatch):
    root = tmp_path / "data"
    data.generate("b", 24, 0, data.split_dir("b", "train", root), workers=1)
    data.generate("b", 12, 1, data.split_dir("b", "test", root), workers=1)
    s = ablation.Settings.fast()
    first = ablation.run(("b",), 1, s, root, tmp_path / "runs", log=lambda m: None)
    assert len(first["b"]) == len(ablation.STEPS) and first["b"][0][0]["n_test"] == 12
    assert len(list((tmp_path / "runs" / "b").glob("*.safetensors"))) == len(ablation.STEPS)

    def no_training(*args, **kwargs):
        raise AssertionError("a kept step was trained again")

    monkeypatch.setattr(training, "train", no_training)
    assert ablation.run(("b",), 1, s, root, tmp_path / "runs", log=lambda m: None) == first
    text = ablation.markdown(first, s)
    assert text.count("\n| b |") == len(ablation.STEPS) and "12 samples" in text


def test_fast_cli_writes_the_table_and_refuses_bad_input(tmp_path):
    out = tmp_path / "ablation.md"
    fig = tmp_path / "ablation.png"
    args = ["reproduce", "ablation", "--fast", "--envs", "b", "--seeds", "1", "--out", str(out),
            "--figure", str(fig)]  # fmt: skip
    result = CliRunner().invoke(app, args)
    assert result.exit_code == 0, result.output
    assert "fast mode" in out.read_text() and out.read_text().count("\n| b |") == 7
    assert fig.read_bytes()[:4] == b"\x89PNG"
    wrong = CliRunner().invoke(app, [*args[:-1], str(tmp_path / "a.txt")])
    assert wrong.exit_code != 0 and "--figure" in str(wrong.exception)
    bad = CliRunner().invoke(app, ["reproduce", "ablation", "--fast", "--envs", "z"])
    assert bad.exit_code != 0 and "--envs" in str(bad.exception)


@pytest.mark.parametrize("env", ["z"])
def test_faithful_cli_refuses_an_unknown_env(env):
    result = CliRunner().invoke(app, ["reproduce", "faithful", "--env", env])
    assert result.exit_code != 0 and "--env" in str(result.exception)


def test_report_only_uses_the_kept_steps_and_trains_none(tmp_path, monkeypatch):
    """``train_for=0``: the table of what is kept (here one seed of the first step), the rest
    marked untrained; nothing is trained and no data is needed."""
    kept = tmp_path / "runs" / "b" / "faithful-s0.safetensors"
    kept.parent.mkdir(parents=True)
    kept.write_bytes(b"")
    scores = {"mae": 0.0123, "auc": 0.9987, "acd": 0.2, "n_test": 5000, "seconds": 1200.0,
              "epochs": 9, "grad_time": 2e-4, "sweep_max": 0.03}  # fmt: skip
    kept.with_suffix(".scores.json").write_text(json.dumps(scores))

    def no_training(*args, **kwargs):
        raise AssertionError("report-only trained a step")

    monkeypatch.setattr(training, "train", no_training)
    out = ablation.run(("b",), 2, ablation.Settings(), tmp_path / "none", tmp_path / "runs",
                       log=lambda m: None, train_for=0)  # fmt: skip
    assert [len(seeds) for seeds in out["b"]] == [1] + [0] * (len(ablation.STEPS) - 1)
    text = ablation.markdown(out, ablation.Settings())
    assert "| b | faithful |" in text and "| 12.30 | 0.9987 | 0.200 |" in text
    assert text.count(" not trained yet |" * 8) == len(ablation.STEPS) - 1


def test_train_for_stops_starting_new_steps(tmp_path, monkeypatch):
    """Once ``train_for`` has passed, steps not yet kept are left for a later run."""
    root = tmp_path / "data"
    data.split_dir("b", "train", root).mkdir(parents=True)
    calls = []

    def fake_train(env, config, name, data_root, out, run_dir):
        calls.append(name)
        time.sleep(0.05)
        out.parent.mkdir(parents=True, exist_ok=True)
        out.write_bytes(b"")
        out.with_suffix(".scores.json").write_text(json.dumps({"mae": 0.01}))

    monkeypatch.setattr(training, "train", fake_train)
    out = ablation.run(("b",), 1, ablation.Settings(), root, tmp_path / "runs",
                       log=lambda m: None, train_for=0.01)  # fmt: skip
    assert calls == ["faithful-s0"]  # started before the limit, the rest not
    assert [len(seeds) for seeds in out["b"]] == [1] + [0] * (len(ablation.STEPS) - 1)


def test_the_table_says_when_table_ii_rows_come_from_different_planners():
    """Rows solved by one planner version: no note; by two (or one before ``t2_git`` was
    recorded): a note naming both."""
    row = {"mae": 0.01, "auc": 0.99, "acd": 0.2, "n_test": 10, "seconds": 1.0, "epochs": 1,
           "grad_time": 1e-4, "sweep_max": 0.01, "t2_success": 3, "t2_median": 2.0,
           "t2_n": 4}  # fmt: skip
    empty = [[] for _ in ablation.STEPS[2:]]
    one = row | {"t2_git": "a" * 40}
    same = {"b": [[one | {"t2_cpu": 1.5}], [one], *empty]}
    text = ablation.markdown(same, ablation.Settings())
    assert "planner versions" not in text
    assert "| 3/4 | 2.00 | 1.50 |" in text and "| 3/4 | 2.00 | – |" in text  # CPU s when recorded
    mixed = {"b": [[row], [row | {"t2_git": "b" * 40}], *empty]}
    note = ablation.markdown(mixed, ablation.Settings())
    assert "2 planner versions (bbbbbbb, before t2_git)" in note


def test_the_table_says_when_timings_come_from_different_code():
    row = {"mae": 0.01, "auc": 0.99, "acd": 0.2, "n_test": 10, "seconds": 1.0, "epochs": 1,
           "grad_time": 1e-4, "sweep_max": 0.01}  # fmt: skip
    empty = [[] for _ in ablation.STEPS[2:]]
    same = {"b": [[row | {"time_git": "a" * 40}], [row | {"time_git": "a" * 40}], *empty]}
    assert "code versions" not in ablation.markdown(same, ablation.Settings())
    mixed = {"b": [[row], [row | {"time_git": "c" * 40}], *empty]}
    note = ablation.markdown(mixed, ablation.Settings())
    assert "d̂+∇ was measured by 2 code versions (before time_git, ccccccc)" in note
    assert "--retime" in note


def test_retime_measures_kept_steps_again_and_keeps_the_rest(tmp_path, monkeypatch):
    """``retime``: every kept step's d̂+∇ and its code version are replaced, the other
    columns stay; without it the kept scores are not touched."""
    runs = tmp_path / "runs"
    weights = runs / "b" / "faithful-s0.safetensors"
    weights.parent.mkdir(parents=True)
    weights.write_bytes(b"")
    cached = weights.with_suffix(".scores.json")
    cached.write_text(json.dumps({"mae": 0.01, "grad_time": 9.0}))
    import gdnplan.models

    monkeypatch.setattr(gdnplan.models, "load_model", lambda path, threads: path)
    monkeypatch.setattr(ablation, "timing", lambda m, env, s: {"grad_time": 1e-4, "time_git": "x"})
    root = tmp_path / "data"
    ablation.run(("b",), 1, ablation.Settings(), root, runs, log=lambda m: None, train_for=0)
    assert json.loads(cached.read_text()) == {"mae": 0.01, "grad_time": 9.0}
    ablation.run(("b",), 1, ablation.Settings(), root, runs, log=lambda m: None, train_for=0,
                 retime=True)  # fmt: skip
    assert json.loads(cached.read_text()) == {"mae": 0.01, "grad_time": 1e-4, "time_git": "x"}


def test_ablation_figure_plots_means_gaps_and_refuses_a_wrong_shape():
    """Two seeds: the MAE point is their mean (mm) with the standard error as its bar; an
    untrained step is a gap (NaN); a results dict with another step count is refused."""
    import numpy as np

    from gdnplan.errors import InputError
    from gdnplan.viz import ablation_figure

    def scores(mae):
        return {"mae": mae, "acd": 0.2, "grad_time": 1e-4, "sweep_max": 0.01}

    results = {"b": [[scores(0.010), scores(0.012)], []]}
    fig = ablation_figure(["faithful", "soft-partners"], results)
    line = fig.axes[0].lines[0]
    np.testing.assert_allclose(line.get_ydata()[0], 11.0)
    assert np.isnan(line.get_ydata()[1]) and len(fig.axes) == 4
    with pytest.raises(InputError, match="one list of seed scores per step"):
        ablation_figure(["faithful"], results)


def _keep(runs, name: str, epochs: int, stale: int | None = None):
    """A kept step ``b/<name>`` trained ``epochs`` epochs (weights, card, scores, checkpoint)."""
    weights = runs / "b" / f"{name}.safetensors"
    (runs / "b" / name).mkdir(parents=True)
    weights.write_bytes(b"")
    weights.with_suffix(".json").write_text(json.dumps({"training": {"epochs": epochs}}))
    weights.with_suffix(".scores.json").write_text(json.dumps({"epochs": epochs}))
    if stale is not None:
        state = {"epoch": epochs, "stale": stale}
        (runs / "b" / name / "checkpoint.json").write_text(json.dumps(state))
    return weights


@pytest.mark.parametrize(
    ("epochs", "stale", "trained", "run_dir_kept"),
    [
        (3, 0, True, True),  # short of the budget, checkpoint: resumed from it
        (3, None, True, True),  # short, no checkpoint (another machine): trained from scratch
        (3, ablation.PATIENCE, False, True),  # stopped early: done
        (5, 0, False, True),  # at the budget: kept
        (9, 0, True, False),  # past the budget: trained again from scratch
    ],
)
def test_a_kept_step_is_trained_to_the_epoch_budget(
    tmp_path, monkeypatch, epochs, stale, trained, run_dir_kept
):
    runs = tmp_path / "runs"
    weights = _keep(runs, "faithful-s0", epochs, stale)
    calls = []

    def fake_train(env, config, name, data_root, out, run_dir):
        calls.append((config.fit.epochs, config.fit.time_budget, run_dir.exists(),
                      out.with_suffix(".scores.json").exists()))  # fmt: skip

    monkeypatch.setattr(training, "train", fake_train)
    ablation.train_step("b", 0, 0, ablation.Settings(epochs=5), tmp_path, runs)
    if not trained:
        assert calls == [] and weights.with_suffix(".scores.json").exists()
        return
    # the budget is epochs, not seconds; the old scores are gone before training
    assert calls == [(5, None, run_dir_kept, False)]


def test_epochs_default_per_environment_and_the_notes_say_which_rows_are_short():
    s = ablation.Settings()
    assert s.epochs_of("d") == ablation.EPOCHS["d"]
    assert ablation.Settings(epochs=3).epochs_of("d") == 3
    row = {"mae": 0.01, "auc": 0.99, "acd": 0.2, "n_test": 10, "seconds": 1.0,
           "grad_time": 1e-4, "sweep_max": 0.01}  # fmt: skip
    empty = [[] for _ in ablation.STEPS[2:]]
    at = row | {"epochs": s.epochs_of("b")}
    text = ablation.markdown({"b": [[at], [at], *empty]}, s)
    assert f"b {s.epochs_of('b')} epochs" in text and "Not yet at the epochs" not in text
    short = ablation.markdown({"b": [[at], [at, row | {"epochs": 2}], *empty]}, s)
    assert "Not yet at the epochs above" in short and "b soft-partners." in short


def test_a_resumed_step_equals_one_trained_straight_through(tmp_path):
    """The epoch budget's premise: training 1 epoch, then resuming to 2, gives the weights of
    2 epochs in one go (the schedule depends on the epoch count only)."""
    from safetensors.numpy import load_file

    root = tmp_path / "data"
    data.generate("b", 24, 0, data.split_dir("b", "train", root), workers=1)
    data.generate("b", 12, 1, data.split_dir("b", "test", root), workers=1)
    fast = ablation.Settings.fast()
    two = ablation.Settings(epochs=2, batch=fast.batch)
    straight = ablation.train_step("b", 1, 0, two, root, tmp_path / "straight")
    ablation.train_step("b", 1, 0, fast, root, tmp_path / "resumed")
    state = tmp_path / "resumed" / "b" / "soft-partners-s0" / "checkpoint.json"
    first = json.loads(state.read_text())["log"]
    resumed = ablation.train_step("b", 1, 0, two, root, tmp_path / "resumed")
    assert json.loads(state.read_text())["log"][:1] == first  # epoch 0 not trained again
    assert json.loads(resumed.with_suffix(".json").read_text())["training"]["epochs"] == 2
    a, b = load_file(straight), load_file(resumed)
    assert a.keys() == b.keys() and all((a[k] == b[k]).all() for k in a)
