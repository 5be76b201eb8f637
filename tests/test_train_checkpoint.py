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


def test_adam_state_resumes_for_a_network_with_unused_parameters(tmp_path):
    """The faithful (argmax) network never uses the soft-kNN temperatures, which so have no
    Adam state: the moments still go back to their own parameters."""
    torch.manual_seed(0)
    net = GraphDistNet(GraphDistNetConfig.faithful().with_(layers=2))
    opt = torch.optim.Adam(net.parameters(), lr=1e-3)
    for p in net.parameters():
        p.grad = None if p is net.log_tau else torch.randn_like(p)
    opt.step()
    assert net.log_tau not in opt.state
    path = tmp_path / "checkpoint.safetensors"
    save_checkpoint(path, net, opt, {"epoch": 1, "lr": 1e-3, "best_state": None})
    fresh = GraphDistNet(GraphDistNetConfig.faithful().with_(layers=2))
    fresh_opt = torch.optim.Adam(fresh.parameters(), lr=1e-3)
    load_checkpoint(path, fresh, fresh_opt)
    for p, q in zip(net.parameters(), fresh.parameters(), strict=True):
        assert (p in opt.state) == (q in fresh_opt.state)
        if p in opt.state:
            torch.testing.assert_close(fresh_opt.state[q]["exp_avg"], opt.state[p]["exp_avg"])
    for q in fresh.parameters():  # a step after resuming runs
        q.grad = None if q is fresh.log_tau else torch.ones_like(q)
    fresh_opt.step()
