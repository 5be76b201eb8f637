"""Torch threads of the learned models: inference runs under the model's count, the caller's
count is restored, the library default and its checks (no timing)."""

from __future__ import annotations

from pathlib import Path

import pytest
import torch

import gdnplan as gp
from gdnplan.cli import set_threads
from gdnplan.models import clearancenet as cn
from gdnplan.models import graphdistnet as gdn
from gdnplan.models import threads as th

WEIGHTS = Path(__file__).resolve().parent.parent / "weights"


@pytest.fixture(autouse=True)
def caller_threads():
    """The caller runs with 3 torch threads (not the models' default) and the library default;
    both are put back after the test."""
    before, default = torch.get_num_threads(), th.inference_threads()
    torch.set_num_threads(3)
    yield 3
    torch.set_num_threads(before)
    th.set_inference_threads(default)


def graphdistnet(threads=None) -> tuple[gp.Scene, gdn.GraphDistNetModel]:
    """A two-way soft-kNN model on the torch path (the compiled whole pass runs no torch)."""
    scene = gp.make_scene("d", seed=5)
    torch.manual_seed(0)
    net = gdn.GraphDistNet(gdn.GraphDistNetConfig.smooth(scale=scene.robot.reach))
    return scene, gdn.GraphDistNetModel(net, threads=threads, fused=False)


def record_threads(monkeypatch, model: gdn.GraphDistNetModel) -> list[tuple[str, int]]:
    """(pass, torch threads) of every forward and backward pass the model runs."""
    seen: list[tuple[str, int]] = []
    estimate, grad = model._estimate, gdn._Tape.grad

    def forward(*args):
        seen.append(("forward", torch.get_num_threads()))
        return estimate(*args)

    def backward(self, robot):
        seen.append(("backward", torch.get_num_threads()))
        return grad(self, robot)

    monkeypatch.setattr(model, "_estimate", forward)
    monkeypatch.setattr(gdn._Tape, "grad", backward)
    return seen


@pytest.mark.parametrize(("threads", "expected"), [(None, th.DEFAULT_THREADS), (2, 2)])
def test_graphdistnet_runs_under_its_count_and_restores_the_callers(
    monkeypatch, caller_threads, threads, expected
):
    scene, model = graphdistnet(threads)
    seen = record_threads(monkeypatch, model)
    q = scene.robot.sample(40, seed=0)
    model.distance(scene, q)
    model.distance_and_grad(scene, q)
    _, gradient = model.distance_deferred_grad(scene, q)
    assert torch.get_num_threads() == caller_threads
    gradient()  # the backward pass of the deferred gradient runs later, under the count too
    assert {kind for kind, _ in seen} == {"forward", "backward"}
    assert {n for _, n in seen} == {expected}
    assert torch.get_num_threads() == caller_threads


def test_library_default_applies_to_models_without_their_own_count(monkeypatch, caller_threads):
    scene, model = graphdistnet()
    seen = record_threads(monkeypatch, model)
    set_threads(2)  # the CLI's --threads: the inference default, torch's global untouched
    assert th.inference_threads() == 2 and torch.get_num_threads() == caller_threads
    model.distance(scene, scene.robot.sample(5, seed=0))
    assert seen == [("forward", 2)]
    model.threads = 1  # a model's own count wins
    model.distance(scene, scene.robot.sample(5, seed=0))
    assert seen[-1] == ("forward", 1) and torch.get_num_threads() == caller_threads


def test_cli_threads_for_training_set_torchs_global_count():
    set_threads(2, torch_global=True)
    assert torch.get_num_threads() == 2 and th.inference_threads() == 2


def test_clearancenet_runs_under_its_count(caller_threads):
    torch.manual_seed(0)
    config = cn.ClearanceNetConfig.for_env("d", hidden=(16, 16))
    model = cn.ClearanceNetModel(cn.ClearanceNet(config).double())
    seen = []
    model.net.register_forward_pre_hook(lambda *_: seen.append(torch.get_num_threads()))
    scene = gp.make_scene("d", seed=4)
    q = scene.robot.sample(10, seed=1)
    model.distance(scene, q)
    model.threads = 2
    model.distance_and_grad(scene, q)
    assert seen == [1, 2] and torch.get_num_threads() == caller_threads


def test_load_model_takes_threads():
    assert gp.load_model(WEIGHTS / "a.safetensors", threads=2).threads == 2
    assert gp.load_model(WEIGHTS / "clearancenet_a.safetensors").threads is None
    with pytest.raises(gp.InputError, match=r"threads: expected an integer in \[1, "):
        gp.load_model(WEIGHTS / "a.safetensors", threads=0)


@pytest.mark.parametrize("bad", [0, -1, 1.5, True, "2"])
def test_bad_thread_counts_are_input_errors(bad):
    with pytest.raises(gp.InputError, match=r"threads: expected an integer in \[1, "):
        th.check_threads(bad)
    with pytest.raises(gp.InputError, match="threads"):
        th.set_inference_threads(bad)
    with pytest.raises(gp.InputError, match="threads"), th.torch_threads(bad):
        pass


def test_torch_threads_restores_the_count_after_an_error(caller_threads):
    with pytest.raises(ZeroDivisionError), th.torch_threads(1) as n:
        assert n == 1 and torch.get_num_threads() == 1
        1 / 0  # noqa: B018
    assert torch.get_num_threads() == caller_threads
