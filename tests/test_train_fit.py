"""The one training loop (gdnplan.train.fit) against a reference transcription of the loops it
replaced, bit for bit, for both learned models; and its schedule's checks."""

import math
import sys
import time
from functools import cache

import numpy as np
import pytest
import torch
from hypothesis import given, settings
from hypothesis import strategies as st

from gdnplan.data import make_shard
from gdnplan.errors import InputError
from gdnplan.models.clearancenet import ClearanceNet, ClearanceNetConfig
from gdnplan.models.graphdistnet import GraphDistNet, GraphDistNetConfig
from gdnplan.train import (
    ClearanceNetLearner,
    FitConfig,
    GraphDistNetLearner,
    GraphDistNetLoss,
    fit,
    tensors,
    validation_split,
)


def reference_fit(learner, c: FitConfig) -> list[tuple[float, float]]:
    """The loop of the former ``train.train`` / ``train_clearancenet.train``, written out:
    per epoch a (seed, epoch) permutation, Adam steps, validation; the learning rate halved
    after 3 stale epochs, a stop after ``patience``, the best state restored.
    Returns (validation score, learning rate) per epoch."""
    net, n = learner.net, len(learner)
    opt = torch.optim.Adam(net.parameters(), lr=c.lr)
    best, best_state, stale, plateau, log = math.inf, None, 0, 0, []
    for epoch in range(c.epochs):
        if stale >= c.patience:
            break
        net.train()
        perm = torch.as_tensor(np.random.default_rng([c.seed, epoch]).permutation(n))
        gen = torch.Generator().manual_seed(c.seed * 100_003 + epoch)
        for s in range(0, n, c.batch):
            loss = learner.loss(perm[s : s + c.batch], gen)
            opt.zero_grad()
            loss.backward()
            opt.step()
        score = learner.validate()["val_score"]
        log.append((score, opt.param_groups[0]["lr"]))
        if score < best:
            best, stale, plateau = score, 0, 0
            best_state = {k: v.detach().clone() for k, v in net.state_dict().items()}
        else:
            stale, plateau = stale + 1, plateau + 1
            if plateau >= 3:
                plateau = 0
                for g in opt.param_groups:
                    g["lr"] /= 2
    net.load_state_dict(best_state)
    return log


@cache
def shard(env: str, n: int):
    return make_shard(env, 0, 0, n)


def clearancenet_learner(seed: int) -> ClearanceNetLearner:
    ds = shard("d", 200)  # env d: dropout 0.5, drawn from torch's global generator
    torch.manual_seed(seed)
    tr, val = validation_split(len(ds), seed)
    return ClearanceNetLearner(
        ClearanceNet(ClearanceNetConfig.for_env("d", hidden=(16,))), ds, tr, val
    )


def graphdistnet_learner(seed: int, cross: str) -> GraphDistNetLearner:
    ds = shard("a", 40)
    torch.manual_seed(seed)
    tr, val = validation_split(len(ds), seed)
    net = GraphDistNet(GraphDistNetConfig(layers=1, hidden=8, mlp=(8,), readout=(8,), cross=cross))
    loss = GraphDistNetLoss(grad_weight=0.1, contact_weight=2.0)
    return GraphDistNetLearner(net, tensors(ds.subset(tr)), tensors(ds.subset(val)), loss)


LEARNERS = {
    "clearancenet": lambda seed: clearancenet_learner(seed),
    "graphdistnet soft_knn": lambda seed: graphdistnet_learner(seed, "soft_knn"),
    "graphdistnet argmax": lambda seed: graphdistnet_learner(seed, "argmax"),  # random partners
}


@pytest.mark.parametrize("model", sorted(LEARNERS))
def test_fit_equals_the_reference_loop_bit_for_bit(model):
    """Same seed, same weights and the same validation scores and learning rates per epoch; a
    learning rate that overshoots makes the run halve it and stop early, so every branch runs."""
    c = FitConfig(batch=16, lr=0.3, epochs=12, patience=4, seed=3)
    a = LEARNERS[model](c.seed)  # each seeds torch's global generator (dropout) when built
    expected = reference_fit(a, c)
    b = LEARNERS[model](c.seed)
    state = fit(b, c)
    assert [(e["val_score"], e["lr"]) for e in state["log"]] == expected
    assert any(lr < c.lr for _, lr in expected) and len(expected) < c.epochs
    assert state["best"] == min(score for score, _ in expected)
    sa, sb = a.net.state_dict(), b.net.state_dict()
    assert sa.keys() == sb.keys() and all(torch.equal(sa[k], sb[k]) for k in sa)


def test_fit_stops_at_the_time_budget_and_keeps_the_starting_weights_when_asked():
    learner = clearancenet_learner(0)
    start = {k: v.clone() for k, v in learner.net.state_dict().items()}
    state = fit(learner, FitConfig(lr=0.0, epochs=5, time_budget=1e-9), start_weights="start")
    assert len(state["log"]) == 1  # the budget is checked before each epoch
    assert all(torch.equal(start[k], v) for k, v in learner.net.state_dict().items())
    assert state["best"] == state["init_val"]["val_score"]


def test_the_cpu_clock_counts_this_process_s_cpu_time_not_the_time_spent_waiting(monkeypatch):
    """An epoch that sleeps 0.3 s (a busy machine) costs the wall clock its sleep and the CPU
    clock nearly nothing: with a 0.2 s budget the wall run stops after one epoch, the CPU run
    goes on."""
    fit_module = sys.modules["gdnplan.train.fit"]  # (gdnplan.train.fit is also the function)
    real = fit_module._epoch

    def waiting(*args):
        time.sleep(0.3)
        return real(*args)

    monkeypatch.setattr(fit_module, "_epoch", waiting)
    runs = {}
    for clock in ("wall", "cpu"):
        c = FitConfig(epochs=3, patience=10, time_budget=0.2, budget_clock=clock)
        runs[clock] = fit(clearancenet_learner(0), c)["log"]
    assert len(runs["wall"]) == 1 and runs["wall"][0]["seconds"] >= 0.3
    assert runs["cpu"][0]["seconds"] < runs["wall"][0]["seconds"]
    assert len(runs["cpu"]) >= len(runs["wall"])


@settings(max_examples=30, deadline=None)
@given(n=st.integers(2, 500), seed=st.integers(0, 2**32 - 1))
def test_validation_split_is_a_seeded_partition_with_a_tenth_held_out(n, seed):
    tr, val = validation_split(n, seed)
    assert len(val) == max(n // 10, 1)
    assert sorted(np.concatenate([tr, val])) == list(range(n))
    np.testing.assert_array_equal(validation_split(n, seed)[1], val)


@pytest.mark.parametrize(
    ("changes", "field"),
    [
        ({"batch": 0}, "batch"),
        ({"epochs": 0}, "epochs"),
        ({"patience": 0}, "patience"),
        ({"batch": True}, "batch"),
        ({"seed": -1}, "seed"),
        ({"lr": float("nan")}, "lr"),
        ({"lr": -1.0}, "lr"),
        ({"time_budget": 0.0}, "time_budget"),
        ({"time_budget": float("inf")}, "time_budget"),
        ({"device": "tpu"}, "device"),
        ({"device": "cuda:7"}, "device"),
        ({"budget_clock": "sundial"}, "budget_clock"),
        ({"budget_clock": None}, "budget_clock"),
    ],
)
def test_bad_schedules_name_the_field(changes, field):
    with pytest.raises(InputError, match=rf"^{field}: "):
        FitConfig(**changes)


@settings(max_examples=4, deadline=None)
@given(weight=st.sampled_from([1e308, 1e300, 1e250]), checkpointed=st.booleans())
def test_a_diverging_run_is_refused_before_its_nan_weights_are_kept(
    tmp_path_factory, weight, checkpointed
):
    """Audit: ``gdnplan train --set grad_weight=1e308`` gave a NaN validation score; no epoch
    was kept, the checkpoint dropped its ``best_state`` key and the run exited with KeyError
    (a rerun then refused the NaN checkpoint as 'shipped weights'). Now one InputError naming
    the fix, and no checkpoint of NaN weights."""
    ds = shard("a", 40)
    tr, val = validation_split(len(ds), 0)
    torch.manual_seed(0)
    net = GraphDistNet(GraphDistNetConfig(layers=1, hidden=8, mlp=(8,), readout=(8,)))
    loss = GraphDistNetLoss(grad_weight=weight)
    learner = GraphDistNetLearner(net, tensors(ds.subset(tr)), tensors(ds.subset(val)), loss)
    ckpt = tmp_path_factory.mktemp("run") / "checkpoint.safetensors" if checkpointed else None
    with pytest.raises(InputError, match=r"training diverged at epoch 0 .*--lr") as error:
        fit(learner, FitConfig(batch=16, epochs=2, seed=0), checkpoint=ckpt)
    assert ckpt is None or not ckpt.exists()
    assert "keeps the last finite epoch" not in str(error.value)  # there was none


def test_a_checkpoint_without_a_best_state_keeps_the_key(tmp_path):
    from gdnplan.train.checkpoint import save_checkpoint
    from gdnplan.train.fit import new_state

    net = torch.nn.Linear(2, 1)
    state = new_state(1e-3)
    save_checkpoint(tmp_path / "c.safetensors", net, torch.optim.Adam(net.parameters()), state)
    assert state["best_state"] is None


@pytest.mark.parametrize("lr", [1e300, 3.5e38, 1001.0])
def test_a_learning_rate_past_the_limit_is_refused(lr):
    """Audit: --lr 1e300 passed the check and torch's Adam step raised "value cannot be
    converted to type float without overflow" (gdnplan train: internal error, exit 3)."""
    with pytest.raises(InputError, match=r"^lr: expected a finite learning rate in \[0, 1000\]"):
        FitConfig(lr=lr)
