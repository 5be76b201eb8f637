import json

import numpy as np
import pytest
import torch

from gdnplan.train import metrics


def test_metrics_hand_computed():
    """MAE, AUC and ACD of four samples: a zero model gradient counts as cos = 0, a zero coal
    gradient is left out (as in gdnplan.evaluate)."""
    d = np.array([-0.02, 0.01, 0.05, 0.10])
    d_hat = np.array([-0.01, 0.03, 0.04, 0.10])
    g = np.array([[1.0, 0.0], [0.0, 2.0], [1.0, 1.0], [0.0, 0.0]])
    g_hat = np.array([[2.0, 0.0], [0.0, 0.0], [-1.0, -1.0], [1.0, 0.0]])
    m = metrics(d_hat, g_hat, d, g, reach=2.0, margin=0.0)
    assert m["mae_m"] == pytest.approx(0.01)
    assert m["mae_reach"] == pytest.approx(0.005)
    assert m["auc"] == 1.0  # the one colliding sample has the lowest d̂
    assert m["acd_n"] == 3
    assert m["acd"] == pytest.approx((0.0 + 1.0 + 2.0) / 3)


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

    from gdnplan.models.graphdistnet import GraphDistNetConfig
    from gdnplan.train import train

    tmp_path = tiny_data
    config = GraphDistNetConfig.smooth().with_(layers=1, grad_weight=0.1)

    def run(name: str, epochs: int) -> dict:
        return train("a", config, epochs=epochs, batch=16, data_root=tmp_path,
                     out=tmp_path / f"{name}.safetensors", run_dir=tmp_path / name)  # fmt: skip

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

    from gdnplan.models.graphdistnet import GraphDistNetConfig
    from gdnplan.train import train

    config = GraphDistNetConfig.smooth().with_(layers=1)
    start, tuned = tiny_data / "start.safetensors", tiny_data / "tuned.safetensors"
    train("a", config, epochs=1, data_root=tiny_data, out=start, run_dir=tiny_data / "r1")
    card = train("a", config, epochs=2, lr=50.0, data_root=tiny_data, out=tuned,
                 run_dir=tiny_data / "r2", init=start)  # fmt: skip
    log = json.loads((tiny_data / "r2" / "checkpoint.json").read_text())["log"]
    assert len(log) == 2 and all(e["val_score"] > card["init"]["val_score"] for e in log)
    a, b = load_file(start), load_file(tuned)
    assert all(torch.equal(a[k], b[k]) for k in a)


def test_a_checkpoint_killed_between_its_two_writes_is_refused(tmp_path, monkeypatch):
    """New checkpoint tensors beside the previous epoch's state are never resumed from."""
    import gdnplan.models.weights as w
    from gdnplan.errors import InputError
    from gdnplan.models.graphdistnet import GraphDistNet, GraphDistNetConfig
    from gdnplan.train import _load_checkpoint, _save_checkpoint

    net = GraphDistNet(GraphDistNetConfig.smooth().with_(layers=1))
    opt = torch.optim.Adam(net.parameters(), lr=1e-3)
    path = tmp_path / "checkpoint.safetensors"
    _save_checkpoint(path, net, opt, {"epoch": 1, "lr": 1e-3, "best_state": None})
    assert _load_checkpoint(path, net, opt)["epoch"] == 1
    with torch.no_grad():
        next(net.parameters()).add_(1.0)  # the next epoch's weights

    def killed(*args):
        raise KeyboardInterrupt

    monkeypatch.setattr(w, "write_json", killed)
    with pytest.raises(KeyboardInterrupt):
        _save_checkpoint(path, net, opt, {"epoch": 2, "lr": 5e-4, "best_state": None})
    with pytest.raises(InputError, match=r"^checkpoint: card checkpoint\.json does not belong"):
        _load_checkpoint(path, net, opt)
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        "checkpoint.json",
        "checkpoint.safetensors",
    ]
