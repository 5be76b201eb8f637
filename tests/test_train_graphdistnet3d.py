"""Streaming GraphDistNet-3D training: every row once per epoch, resuming at the same batch,
a resumed run continuing its checkpoint and refusing other settings."""

from __future__ import annotations

import numpy as np
import pytest

from gdnplan.data.shards3d import generate3d
from gdnplan.errors import InputError
from gdnplan.models import load_model
from gdnplan.models.graphdistnet3d import GraphDistNet3DModel, load_graphdistnet3d
from gdnplan.models.weights import read_card
from gdnplan.train.graphdistnet3d import (
    Train3DConfig,
    batches,
    export_weights,
    shard_files,
    train3d,
)


@pytest.fixture(scope="module")
def split(tmp_path_factory):
    root = tmp_path_factory.mktemp("data3d")
    generate3d("ur5e_boxes", 150, 0, root / "train", workers=1, shard_size=50)
    generate3d("ur5e_boxes", 50, 1, root / "val", workers=1, shard_size=50)
    return root


def test_an_epoch_visits_every_row_once_and_resumes_in_place(split):
    files = shard_files(split / "train")
    seen = [(step, int(s["scene_seed"][0]), tuple(r)) for step, s, r in batches(files, 16, 0, 3)]
    assert [s for s, _, _ in seen] == list(range(len(seen)))
    per_shard: dict[int, list] = {}
    for _, shard, rows in seen:
        per_shard.setdefault(shard, []).extend(rows)
    assert all(sorted(r) == list(range(50)) for r in per_shard.values()) and len(per_shard) == 3
    later = [
        (step, int(s["scene_seed"][0]), tuple(r)) for step, s, r in batches(files, 16, 0, 3, 5)
    ]
    assert later == seen[5:]
    other = [tuple(r) for _, _, r in batches(files, 16, 0, 4)]
    assert other != [r for _, _, r in seen]


def test_distance_only_training_takes_steps(split, tmp_path):
    c = Train3DConfig(batch=25, validate_every=2, n_val=20, grad_weight=0.0)
    state = train3d(split / "train", split / "val", tmp_path, c, time_budget=0, echo=lambda s: None)
    assert state["step"] == 2 and np.isfinite(state["log"][-1]["mae_m"])


@pytest.mark.slow
def test_training_resumes_from_its_checkpoint(split, tmp_path):
    c = Train3DConfig(batch=25, validate_every=2, n_val=20, grad_weight=0.1)
    first = train3d(split / "train", split / "val", tmp_path, c, time_budget=0, echo=lambda s: None)
    assert first["step"] == 2 and len(first["log"]) == 1
    again = train3d(split / "train", split / "val", tmp_path, c, time_budget=0, echo=lambda s: None)
    assert again["step"] == 4 and len(again["log"]) == 2
    assert again["samples"] == 100 and np.isfinite(again["log"][-1]["mae_m"])
    with pytest.raises(InputError, match="other settings"):
        train3d(split / "train", split / "val", tmp_path, Train3DConfig(batch=10), time_budget=0)
    card = export_weights(tmp_path, tmp_path / "w.safetensors", split / "val", n_test=30)
    assert card["test"]["n"] == 30 and card["acceptance"]["met"] is False
    assert read_card(tmp_path / "w.safetensors")["model"] == "graphdistnet3d"
    model = load_graphdistnet3d(tmp_path / "w.safetensors")
    assert model.card["robot"] == "ur5e" and model.config.rim == 8
    assert isinstance(load_model(tmp_path / "w.safetensors"), GraphDistNet3DModel)


def test_cloud_batches_use_the_knn_graph_of_each_scene():
    import torch

    from gdnplan.data.samples3d import env_robot3d, make_shard3d
    from gdnplan.graph3d import point_cloud_graph, robot_graph3d
    from gdnplan.models.graphdistnet3d import GraphDistNet3D, GraphDistNet3DConfig
    from gdnplan.train.graphdistnet3d import CLOUD_K, Batch3D

    shard = make_shard3d("ur5e_cloud", 0, 0, 50)
    graph = robot_graph3d(env_robot3d("ur5e_cloud"))
    b = Batch3D(graph, shard, np.arange(4))
    knn = point_cloud_graph(shard["points"][0], CLOUD_K)
    assert b.obstacles.nodes.shape == (1, 400, 3)
    np.testing.assert_array_equal(b.obstacles.nbr[0].numpy(), knn.nbr)
    d, g = b.run(GraphDistNet3D(GraphDistNet3DConfig(scale=1.2)), graph, False)
    assert d.shape == (4,) and g.shape == (4, 6) and torch.isfinite(g).all()


def _weights(tmp_path, config, seed: int = 0):
    """A weights file of an untrained network of ``config`` (as export_weights writes it)."""
    import torch

    from gdnplan.models.graphdistnet3d import GraphDistNet3D
    from gdnplan.models.weights import write_weights

    torch.manual_seed(seed)
    net = GraphDistNet3D(config)
    path = tmp_path / f"w{seed}.safetensors"
    write_weights(path, net.state_dict(), {"model": "graphdistnet3d", "config": config.to_dict()})
    return path, net


def test_init_starts_a_new_run_at_the_weights_function(split, tmp_path):
    from gdnplan.train.graphdistnet3d import evaluate3d, network_config

    path, net = _weights(tmp_path, network_config().with_(layers=2), seed=1)
    assert network_config(path) == net.config
    c = Train3DConfig(batch=25, validate_every=2, n_val=20, grad_weight=0.0, lr=0.0, min_lr=0.0)
    run = tmp_path / "run"
    quiet = lambda s: None  # noqa: E731
    state = train3d(split / "train", split / "val", run, c, time_budget=0, echo=quiet, init=path)
    assert state["log"][0]["mae_m"] == pytest.approx(evaluate3d(net, split / "val", 20)["mae_m"])
    assert read_card(run / "checkpoint.safetensors", "c")["settings"]["init"] == str(path)
    other = tmp_path / "other"  # without init the run's seed (0) draws another network
    fresh = train3d(
        split / "train", split / "val", other, c, network_config().with_(layers=2), 0, quiet
    )
    assert fresh["log"][0]["mae_m"] != pytest.approx(state["log"][0]["mae_m"])


def test_init_adds_the_min_readout_to_a_plain_network(split, tmp_path):
    import torch

    from gdnplan.data.samples3d import env_robot3d
    from gdnplan.graph3d import robot_graph3d
    from gdnplan.models.graphdistnet3d import GraphDistNet3D, init_from_weights
    from gdnplan.train.graphdistnet3d import Batch3D, network_config, read_shard

    path, plain = _weights(tmp_path, network_config().with_(layers=2))
    config = network_config(path, min_readout=True)
    assert config == plain.config.with_(min_readout=True)
    net = GraphDistNet3D(config)
    fresh = init_from_weights(net, path)
    assert set(fresh) == {k for k in net.state_dict() if k not in plain.state_dict()}
    assert fresh and all(k.startswith(("node_head.", "log_tau_min")) for k in fresh)
    graph = robot_graph3d(env_robot3d("ur5e_boxes"))
    b = Batch3D(graph, read_shard(shard_files(split / "val")[0]), np.arange(8))
    with torch.no_grad():  # the new readout starts at zero: the plain network's function
        torch.testing.assert_close(b.distance(net, graph), b.distance(plain, graph))


def test_init_refuses_weights_that_do_not_fit(tmp_path):
    from gdnplan.models.graphdistnet3d import GraphDistNet3D, init_from_weights
    from gdnplan.train.graphdistnet3d import network_config

    path, _ = _weights(tmp_path, network_config().with_(layers=2))
    with pytest.raises(InputError, match="does not fit"):
        init_from_weights(GraphDistNet3D(network_config().with_(layers=3)), path)
    with pytest.raises(InputError, match="scale"):
        init_from_weights(GraphDistNet3D(network_config().with_(layers=2, scale=2.0)), path)


def test_graphdistnet3d_reexports_the_concept_modules_names():
    """gdnplan.train.graphdistnet3d keeps every name it had (streaming, batches, report)."""
    from gdnplan.train import batch3d, graphdistnet3d, report3d, shard_stream3d

    for module in (shard_stream3d, batch3d, report3d):
        for name in module.__all__:
            assert getattr(graphdistnet3d, name) is getattr(module, name), name
            assert name in graphdistnet3d.__all__


@pytest.mark.parametrize(
    ("changes", "field"),
    [
        ({"batch": 0}, "batch"),
        ({"validate_every": 0}, "validate_every"),
        ({"n_val": 0}, "n_val"),
        ({"seed": -1}, "seed"),
        ({"lr": 1e300}, "lr"),
        ({"lr": float("nan")}, "lr"),
        ({"min_lr": -1.0}, "min_lr"),
        ({"min_lr": 1.0}, "min_lr"),  # above lr: nothing would train
        ({"grad_weight": float("nan")}, "grad_weight"),
        ({"contact_scale": 0.0}, "contact_scale"),
    ],
)
def test_bad_3d_training_settings_name_the_field(changes, field):
    """Audit: Train3DConfig took anything (batch 0, NaN weights, lr 1e300) and failed deep in
    the loop, or trained nothing."""
    with pytest.raises(InputError, match=rf"^{field}: "):
        Train3DConfig(**changes)


@pytest.mark.parametrize("budget", [None, float("inf"), float("nan"), -1.0])
def test_a_run_that_could_never_end_is_refused(tmp_path, budget):
    """Audit: min_lr = 0 without a time budget (or with an infinite one) looped for ever."""
    c = Train3DConfig(lr=0.0, min_lr=0.0)
    with pytest.raises(InputError, match=r"min_lr|time_budget"):
        train3d(tmp_path / "t", tmp_path / "v", tmp_path / "run", c, time_budget=budget)
