"""Training GraphDistNet (gdnplan.train.graphdistnet): resuming, fine-tuning, cards, settings."""

import json
import warnings

import pytest
import torch

from gdnplan.errors import InputError
from gdnplan.models.graphdistnet import GraphDistNetConfig
from gdnplan.train import (
    FitConfig,
    GraphDistNetLoss,
    TrainConfig,
    card_settings,
    split_config,
    train,
)


@pytest.fixture
def tiny_data(tmp_path):
    """60 training and 20 test samples of environment (a) under ``tmp_path``."""
    from gdnplan.data import generate, split_dir

    for split, n, seed in (("train", 60, 0), ("test", 20, 1)):
        generate("a", n, seed, split_dir("a", split, tmp_path), workers=1)
    return tmp_path


def test_interrupted_training_resumes_to_the_same_weights(tiny_data):
    """Two epochs in one go equal one epoch, then a resumed run to two epochs (the checkpoint
    holds weights, Adam's moments, the best state and the log)."""
    from safetensors.torch import load_file

    tmp_path = tiny_data
    network, loss = GraphDistNetConfig.smooth().with_(layers=1), GraphDistNetLoss(grad_weight=0.1)

    def run(name: str, epochs: int) -> dict:
        config = TrainConfig(network, loss, FitConfig(epochs=epochs, batch=16))
        return train("a", config, data_root=tmp_path, out=tmp_path / f"{name}.safetensors",
                     run_dir=tmp_path / name)  # fmt: skip

    straight = run("straight", 2)
    run("resumed", 1)
    resumed = run("resumed", 2)
    log = json.loads((tmp_path / "resumed" / "checkpoint.json").read_text())["log"]
    assert [e["epoch"] for e in log] == [0, 1]
    a, b = load_file(tmp_path / "straight.safetensors"), load_file(tmp_path / "resumed.safetensors")
    assert set(a) == set(b) and all(torch.equal(a[k], b[k]) for k in a)
    untimed = [
        {k: v for k, v in c["test"].items() if "second" not in k} for c in (resumed, straight)
    ]
    assert untimed[0] == untimed[1]


def test_fine_tuning_keeps_the_starting_weights_when_no_epoch_beats_them(tiny_data):
    """A learning rate that wrecks the network: the starting weights win the validation."""
    from safetensors.torch import load_file

    network = GraphDistNetConfig.smooth().with_(layers=1)
    start, tuned = tiny_data / "start.safetensors", tiny_data / "tuned.safetensors"
    first = TrainConfig(network, fit=FitConfig(epochs=1))
    train("a", first, data_root=tiny_data, out=start, run_dir=tiny_data / "r1")
    tune = TrainConfig(network, fit=FitConfig(epochs=2, lr=50.0), init=start)
    card = train("a", tune, data_root=tiny_data, out=tuned, run_dir=tiny_data / "r2")
    log = json.loads((tiny_data / "r2" / "checkpoint.json").read_text())["log"]
    assert len(log) == 2 and all(e["val_score"] > card["init"]["val_score"] for e in log)
    a, b = load_file(start), load_file(tuned)
    assert all(torch.equal(a[k], b[k]) for k in a)


def test_cards_record_the_loss_apart_and_old_flat_cards_still_give_it(tiny_data):
    """A new card: ``config`` is the architecture, ``training.loss`` the loss; --init of it
    gives both back. An old flat card (loss weights in ``config``) gives the same split."""
    from gdnplan.assets import weights_file

    network = GraphDistNetConfig.smooth().with_(layers=1)
    loss = GraphDistNetLoss(grad_weight=0.1, contact_weight=3.0)
    out = tiny_data / "w.safetensors"
    train("a", TrainConfig(network, loss, FitConfig(epochs=1)), data_root=tiny_data, out=out,
          run_dir=tiny_data / "r")  # fmt: skip
    card = json.loads(out.with_suffix(".json").read_text())
    assert "grad_weight" not in card["config"] and card["training"]["loss"] == loss.to_dict()
    got_network, got_loss = split_config(card_settings(out))
    assert got_loss == loss and got_network.layers == 1
    old = json.loads(weights_file("c").with_suffix(".json").read_text())  # a flat shipped card
    old_network, old_loss = split_config(card_settings(weights_file("c")))
    assert old_loss.grad_weight == old["config"]["grad_weight"] == 0.1
    assert old_network == GraphDistNetConfig.from_dict(old["config"])


def test_the_old_call_still_trains_with_a_deprecation_warning(tiny_data):
    network = GraphDistNetConfig.smooth().with_(layers=1)
    with pytest.warns(DeprecationWarning, match="TrainConfig"):
        card = train("a", network, epochs=1, batch=16, data_root=tiny_data,
                     out=tiny_data / "old.safetensors", run_dir=tiny_data / "old")  # fmt: skip
    assert card["training"]["batch"] == 16 and card["training"]["epochs"] == 1
    with warnings.catch_warnings(), pytest.raises(TypeError, match="unexpected"):
        warnings.simplefilter("ignore")
        train("a", network, batches=16)


@pytest.mark.parametrize(
    ("changes", "field"),
    [({"n_train": 1}, "n_train"), ({"n_train": 2.5}, "n_train"),
     ({"compile": True, "loss": GraphDistNetLoss(grad_weight=0.1)}, "compile")],
)  # fmt: skip
def test_bad_train_configs_name_the_field(changes, field):
    with pytest.raises(InputError, match=rf"^{field}: "):
        TrainConfig(**changes)


def test_a_compiled_step_network_is_kept():
    """``--compile``: the learner takes the torch.compile wrapper (whose truth value raises)."""
    from gdnplan.models.graphdistnet import GraphDistNet
    from gdnplan.train.graphdistnet import GraphDistNetLearner

    net = GraphDistNet(GraphDistNetConfig.faithful())
    compiled = torch.compile(net, dynamic=True)
    assert GraphDistNetLearner(net, None, None, None, step_net=compiled).step_net is compiled
    assert GraphDistNetLearner(net, None, None, None).step_net is net


@pytest.mark.parametrize(
    ("scale", "message"), [(float("nan"), "NaN or infinite"), (1e4, "overflow")]
)
def test_library_init_refuses_weights_that_cannot_train(tiny_data, scale, message):
    """Audit: ``TrainConfig(init=…)`` from Python loaded NaN weights unchecked (only the CLI
    checked them), and weights within the magnitude bound whose network overflows trained
    an epoch and were reported as a run that "diverged at epoch 0"."""
    from safetensors.torch import load_file

    from gdnplan.models.weights import read_card, write_weights

    network = GraphDistNetConfig.smooth().with_(layers=1)
    start = tiny_data / "start.safetensors"
    train("a", TrainConfig(network, fit=FitConfig(epochs=1)), data_root=tiny_data, out=start,
          run_dir=tiny_data / "r1")  # fmt: skip
    tensors = {k: v * scale for k, v in load_file(str(start)).items()}
    bad = write_weights(tiny_data / "bad.safetensors", tensors, read_card(start))
    tune = TrainConfig(network, fit=FitConfig(epochs=1), init=bad)
    with pytest.raises(InputError, match=message) as info:
        train("a", tune, data_root=tiny_data, out=tiny_data / "t.safetensors",
              run_dir=tiny_data / "r2")  # fmt: skip
    assert "bad.safetensors" in str(info.value)


def test_library_init_takes_a_bare_tensors_file_but_checks_its_values(tiny_data):
    """A hand-made warm start without a card loads (the warm-start tests write such files);
    its tensors are still checked: NaN is refused naming the file."""
    from safetensors.torch import load_file, save_file

    network = GraphDistNetConfig.smooth().with_(layers=1)
    start = tiny_data / "start.safetensors"
    train("a", TrainConfig(network, fit=FitConfig(epochs=1)), data_root=tiny_data, out=start,
          run_dir=tiny_data / "r1")  # fmt: skip
    tensors = load_file(str(start))
    save_file(tensors, str(tiny_data / "bare.safetensors"))
    tune = TrainConfig(network, fit=FitConfig(epochs=1), init=tiny_data / "bare.safetensors")
    train("a", tune, data_root=tiny_data, out=tiny_data / "t.safetensors", run_dir=tiny_data / "r2")
    save_file({k: v * float("nan") for k, v in tensors.items()}, str(tiny_data / "nan.safetensors"))
    tune = TrainConfig(network, fit=FitConfig(epochs=1), init=tiny_data / "nan.safetensors")
    with pytest.raises(InputError, match=r"nan\.safetensors"):
        train("a", tune, data_root=tiny_data, out=tiny_data / "u.safetensors",
              run_dir=tiny_data / "r3")  # fmt: skip


@pytest.mark.parametrize("kind", ["missing", "folder", "pipe"])
def test_init_tensors_refuses_what_is_no_regular_file(tmp_path, kind):
    """--init from Python: a folder or a named pipe (reading one waits for ever) is refused by
    name before anything reads it."""
    import os

    from gdnplan.train.graphdistnet import init_tensors

    path = tmp_path / "w.safetensors"
    if kind == "folder":
        path.mkdir()
    elif kind == "pipe":
        os.mkfifo(path)
    with pytest.raises(InputError, match="not a regular file"):
        init_tensors(path)
