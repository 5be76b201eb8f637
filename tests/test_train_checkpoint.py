"""Training checkpoints (gdnplan.train.checkpoint): a torn write is refused, and resuming
checks the settings (older checkpoints' removed options at their defaults pass)."""

import pytest
import torch

from gdnplan.errors import InputError
from gdnplan.models.graphdistnet import GraphDistNet, GraphDistNetConfig
from gdnplan.train import check_resume, load_checkpoint, save_checkpoint


def test_a_checkpoint_killed_between_its_two_writes_is_refused(tmp_path, monkeypatch):
    """New checkpoint tensors beside the previous epoch's state are never resumed from."""
    import gdnplan.models.weights as w

    net = GraphDistNet(GraphDistNetConfig.smooth().with_(layers=1))
    opt = torch.optim.Adam(net.parameters(), lr=1e-3)
    path = tmp_path / "checkpoint.safetensors"
    save_checkpoint(path, net, opt, {"epoch": 1, "lr": 1e-3, "best_state": None})
    assert load_checkpoint(path, net, opt)["epoch"] == 1
    with torch.no_grad():
        next(net.parameters()).add_(1.0)  # the next epoch's weights

    def killed(*args):
        raise KeyboardInterrupt

    monkeypatch.setattr(w, "write_json", killed)
    with pytest.raises(KeyboardInterrupt):
        save_checkpoint(path, net, opt, {"epoch": 2, "lr": 5e-4, "best_state": None})
    with pytest.raises(InputError, match=r"^checkpoint: card checkpoint\.json does not belong"):
        load_checkpoint(path, net, opt)
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        "checkpoint.json",
        "checkpoint.safetensors",
    ]


def test_resume_check_names_changed_settings_and_accepts_removed_defaults(tmp_path):
    config = {"layers": 4, "grad_weight": 0.0}
    old = {"settings": {"config": {**config, "activation": "leaky_relu", "max_edge": None},
                        "batch": 256}}  # fmt: skip
    check_resume(old, {"config": config, "batch": 256}, tmp_path / "c.safetensors")
    with pytest.raises(InputError, match=r"--set grad_weight"):
        check_resume(old, {"config": {**config, "grad_weight": 0.1}, "batch": 256}, tmp_path)
    with pytest.raises(InputError, match=r"\(batch\)"):
        check_resume(old, {"config": config, "batch": 16}, tmp_path)
