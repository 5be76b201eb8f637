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
