"""Thread counts beyond the documented bound (gdnplan.models.threads.MAX_THREADS), bools and
non-integers are InputErrors in every API that takes one, and exit 2 with one ``error:`` line
in every command's ``--threads``; nothing is set before the check."""

from __future__ import annotations

import pytest
import torch
import typer
from typer.testing import CliRunner

import gdnplan as gp
from gdnplan.cli import run, set_threads
from gdnplan.models import clearancenet as cn
from gdnplan.models import graphdistnet as gdn
from gdnplan.models import threads as th
from gdnplan.models.fields import shown
from gdnplan.models.graphdistnet3d import GraphDistNet3D, GraphDistNet3DConfig
from gdnplan.models.graphdistnet3d.model import GraphDistNet3DModel

BAD = [0, -1, th.MAX_THREADS + 1, 100_000, 2**63, 10**5000, True, False, 1.5, "2", [2]]
SQUARE = "problems/planar2_square.toml"


@pytest.fixture(autouse=True)
def keep_threads():
    """Torch's count and the library default are put back after every test."""
    before, default = torch.get_num_threads(), th.inference_threads()
    yield
    torch.set_num_threads(before)
    th.set_inference_threads(default)


def test_the_bound_is_four_per_core_and_at_least_256():
    import os

    assert th.MAX_THREADS == max(256, 4 * (os.cpu_count() or 1))
    assert th.check_threads(th.MAX_THREADS) == th.MAX_THREADS
    assert th.check_threads(None) is None


@pytest.mark.parametrize("bad", BAD, ids=lambda v: shown(v, 20))
def test_check_threads_refuses(bad):
    with pytest.raises(
        gp.InputError, match=rf"threads: expected an integer in \[1, {th.MAX_THREADS}\] \(the limit"
    ):
        th.check_threads(bad)
    with pytest.raises(gp.InputError, match="threads"):
        th.set_inference_threads(bad)
    with pytest.raises(gp.InputError, match="threads"), th.torch_threads(bad):
        pass


def test_set_inference_threads_refuses_none():
    with pytest.raises(gp.InputError, match="threads"):
        th.set_inference_threads(None)


@pytest.mark.parametrize("bad", [100_000, 2**63, True, th.MAX_THREADS + 1], ids=repr)
@pytest.mark.parametrize("weights", ["b", "clearancenet_b", "ur5e_storage3d"])
def test_load_model_refuses(weights, bad):
    with pytest.raises(gp.InputError, match="threads: expected an integer"):
        gp.load_model(weights, threads=bad)


@pytest.mark.parametrize("bad", [100_000, 2**63, True, 0], ids=repr)
def test_model_constructors_refuse(bad):
    scene = gp.make_scene("b", seed=0)
    net = gdn.GraphDistNet(gdn.GraphDistNetConfig.smooth(scale=scene.robot.reach))
    with pytest.raises(gp.InputError, match="threads"):
        gdn.GraphDistNetModel(net, threads=bad)
    config = cn.ClearanceNetConfig.for_env("b", hidden=(8,))
    with pytest.raises(gp.InputError, match="threads"):
        cn.ClearanceNetModel(cn.ClearanceNet(config), threads=bad)
    with pytest.raises(gp.InputError, match="threads"):
        GraphDistNet3DModel(GraphDistNet3D(GraphDistNet3DConfig(hidden=8)), threads=bad)


def test_a_count_set_on_the_model_later_is_checked_when_set():
    model = gp.load_model("b")
    scene = gp.make_scene("b", seed=0)
    with pytest.raises(gp.InputError, match="threads: expected an integer"):
        model.threads = 100_000
    model.threads = 2
    assert model.distance(scene, scene.robot.sample(2, seed=0)).shape == (2,)


@pytest.mark.parametrize("bad", [100_000, 2**63, 0, -3], ids=repr)
def test_cli_set_threads_refuses_before_setting_anything(bad):
    before, default = torch.get_num_threads(), th.inference_threads()
    with pytest.raises(gp.InputError, match="--threads: expected an integer"):
        set_threads(bad, torch_global=True)
    assert torch.get_num_threads() == before and th.inference_threads() == default


def _command() -> typer.Typer:
    """The whole ``gdnplan`` entry point (exit codes and ``error:`` lines of
    :func:`gdnplan.cli.run`) as one typer app for CliRunner."""
    app = typer.Typer(add_completion=False)
    extra = {"ignore_unknown_options": True, "allow_extra_args": True, "help_option_names": []}

    @app.command(context_settings=extra)
    def gdnplan(ctx: typer.Context) -> None:
        run(ctx.args)

    return app


COMMANDS = {  # each command with --threads, args that reach its set_threads call quickly
    "plan": ["plan", SQUARE, "--collision", "coal"],
    "fetch": ["fetch", "--collision", "coal"],
    "fetch3d": ["fetch", "--3d"],
    "table2": ["reproduce", "table2", "--n", "1", "--out", "{tmp}/t.md"],
    "faithful": ["reproduce", "faithful", "--env", "b", "--out", "{tmp}/w.safetensors"],
    "train": ["train", "--env", "b", "--out", "{tmp}/w.safetensors"],
    "train_cn": ["train", "--env", "b", "--model", "clearancenet", "--out", "{tmp}/w.safetensors"],
}


@pytest.mark.parametrize("bad", ["100000", str(2**63), "0", "-1"])
@pytest.mark.parametrize("command", sorted(COMMANDS))
def test_cli_threads_out_of_range_exit_2_with_one_error_line(command, bad, tmp_path):
    args = [a.format(tmp=tmp_path) for a in COMMANDS[command]] + ["--threads", bad]
    result = CliRunner().invoke(_command(), args)
    lines = [line for line in result.output.splitlines() if line.startswith("error:")]
    assert result.exit_code == 2, result.output
    assert len(lines) == 1 and "--threads" in lines[0], result.output
    assert "libgomp" not in result.output and "internal error" not in result.output


def test_cli_threads_non_integer_is_a_usage_error(tmp_path):
    result = CliRunner().invoke(_command(), ["plan", SQUARE, "--threads", "1.5"])
    assert result.exit_code == 2 and "error:" in result.output
