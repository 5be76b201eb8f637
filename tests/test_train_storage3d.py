"""Training on ``ur5e_storage`` shards: a robot graph per sample (fingers open or holding the
stick) giving the model's own d̂ and ∂d̂/∂q on each scene; a run takes steps and exports a
card naming the environment."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from gdnplan.data.samples3d import SCENE_SAMPLES, make_shard3d
from gdnplan.data.samples_storage3d import HOLDING, OPEN, storage_scene_of
from gdnplan.data.shards3d import generate3d
from gdnplan.models.graphdistnet3d import GraphDistNet3D, GraphDistNet3DConfig
from gdnplan.models.graphdistnet3d.model import GraphDistNet3DModel
from gdnplan.train.batch_storage3d import StorageBatch3D
from gdnplan.train.graphdistnet3d import Train3DConfig, export_weights, train3d


@pytest.fixture(scope="module")
def shard():
    return make_shard3d("ur5e_storage", 2, 0, 6 * SCENE_SAMPLES, near=0.3)


def test_a_storage_batch_gives_the_models_distance_and_gradient_on_every_scene(shard):
    torch.manual_seed(0)
    net = GraphDistNet3D(GraphDistNet3DConfig(scale=1.2))
    rows = np.random.default_rng(0).permutation(len(shard["d"]))[:60]
    b = StorageBatch3D(net.config.rim, shard, rows)
    assert sorted(b.rows) == sorted(rows) and len(b.parts) == 2
    n_open, n_held = (p.nodes.shape[1] for p in b.parts)
    assert n_held == n_open + 8  # the held stick's box
    d, g = b.run(net, None, False)
    model = GraphDistNet3DModel(net, {}, threads=1, fused=False)  # card-less: no fit checks
    for s in np.unique(shard["scene"][rows]):
        scene = storage_scene_of(shard["storage"][s], shard["placement"][s], shard["variant"][s])
        here = shard["scene"][b.rows] == s
        ref_d, ref_g = model.learned_distance_and_grad(scene, shard["q"][b.rows[here]])
        np.testing.assert_allclose(d.detach().numpy()[here], ref_d, atol=2e-5)
        np.testing.assert_allclose(g.detach().numpy()[here], ref_g, atol=2e-4)
    np.testing.assert_allclose(b.distance(net).detach().numpy(), d.detach().numpy(), atol=1e-6)
    assert np.array_equal(b.d.numpy(), shard["d"][b.rows].astype(np.float32))
    assert {OPEN, HOLDING} <= set(shard["variant"][shard["scene"][rows]].tolist())


def test_a_storage_run_takes_steps_and_exports_its_env(tmp_path):
    generate3d("ur5e_storage", 100, 0, tmp_path / "train", workers=1, shard_size=50)
    generate3d("ur5e_storage", 50, 1, tmp_path / "val", workers=1, shard_size=50)
    c = Train3DConfig(batch=25, validate_every=2, n_val=20, grad_weight=0.0)
    run = tmp_path / "run"
    state = train3d(tmp_path / "train", tmp_path / "val", run, c, time_budget=0, echo=lambda s: 0)
    assert state["step"] == 2 and np.isfinite(state["log"][-1]["mae_m"])
    card = export_weights(run, tmp_path / "w.safetensors", tmp_path / "val", n_test=20)
    assert card["env"] == "ur5e_storage" and card["test"]["n"] == 20
