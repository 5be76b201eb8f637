"""The fetch sequence: per-sample robot graphs, reach-in end to end, the held stick's clearance."""

from pathlib import Path

import numpy as np
import pytest
import torch
from typer.testing import CliRunner

import gdnplan as gp
from gdnplan import data
from gdnplan.ccd_contact import CONTACT_ALLOWANCE
from gdnplan.cli import app
from gdnplan.fetch import STAGES, run_fetch, stick_clearance
from gdnplan.models.graphdistnet import GraphDistNet, GraphDistNetConfig, GraphDistNetModel
from gdnplan.train import predict, tensors

ROOT = Path(__file__).resolve().parent.parent
RESTING = 1e-9  # m: coal's reading of the resting contact (d = 0 by design; −4e-16 seen)
WEIGHTS = ROOT / "weights" / "ur5e.safetensors"
needs_weights = pytest.mark.skipif(not WEIGHTS.exists(), reason="weights/ur5e not trained")


def test_padded_per_sample_robot_graphs_equal_single_sample_evaluation():
    ds = data.make_shard("ur5e", seed=1, start=0, n=12)
    assert len(ds.variants()) > 1  # open, closed and holding robots mixed in one batch
    robot = data.env_robot("ur5e")
    config = GraphDistNetConfig.smooth(
        scale=robot.reach, origin=tuple(robot.chain.joint_origins[0])
    )
    torch.manual_seed(0)
    net = GraphDistNet(config)
    t = tensors(ds, config)
    assert t.robot is not None and not t.robot.mask.all()  # some graphs are padded
    d, g = predict(net, t, chunk=5)
    model = GraphDistNetModel(net)
    for i in range(len(ds)):
        d1, g1 = model.distance_and_grad(ds.scene(i), ds.q[i])
        assert d[i] == pytest.approx(d1[0], abs=1e-6)
        np.testing.assert_allclose(g[i], g1[0], atol=1e-6)


@needs_weights
def test_reach_in_with_graphdistnet_end_to_end_is_certified_by_coal():
    problem = gp.Problem.from_toml(ROOT / "problems" / "fetch_reach.toml")
    result = gp.plan(problem, collision="graphdistnet")  # weights/ur5e via the scene name
    assert result.success, result.reason
    ok, dmin = gp.verify_path(problem.scene, result.q)
    assert ok and dmin > 0
    np.testing.assert_allclose(result.q[0], problem.start)
    np.testing.assert_allclose(result.q[-1], problem.goal, atol=1e-3)


def test_bring_out_keeps_the_held_stick_clear_of_the_storage():
    (stage,) = run_fetch(0, collision="coal", stages=("bring_out",))
    assert stage.success, stage.detail
    assert "stick" in [p.name for p in stage.scene.robot.polygons]  # the stick is robot geometry
    assert not any(
        len(o) == 4 and np.allclose(o, stage.scene.info["stick"]) for o in stage.scene.obstacles
    )
    assert stick_clearance(stage.scene, stage.q) > 0
    assert gp.verify_path(stage.scene, stage.q)[0]


@pytest.mark.slow
@needs_weights
def test_bring_out_with_graphdistnet_keeps_the_stick_clear():
    (stage,) = run_fetch(0, collision="graphdistnet", stages=("bring_out",))
    assert stage.success, stage.detail
    assert stick_clearance(stage.scene, stage.q) > 0
    assert gp.verify_path(stage.scene, stage.q)[0]


@pytest.mark.slow
def test_fetch_cli_runs_every_stage(tmp_path):
    out = tmp_path / "fetch.gif"
    result = CliRunner().invoke(app, ["fetch", "--collision", "coal", "--animate", str(out)])
    assert result.exit_code == 0, result.output
    for name in STAGES:
        assert name in result.output
    assert out.read_bytes()[:3] == b"GIF"


@pytest.mark.parametrize("seed", [2, 4])  # layouts where coal rounds the resting contact below 0
def test_grasp_accepts_the_stick_resting_on_its_shelf(seed):
    (stage,) = run_fetch(seed, collision="coal", stages=("grasp",))
    assert stage.success and abs(stage.min_distance) <= RESTING  # d = 0 by design


def test_unknown_stage_is_bad_input():
    with pytest.raises(gp.InputError):
        run_fetch(0, collision="coal", stages=("dance",))


@pytest.mark.parametrize("seed", [0, 2])
def test_the_lifts_min_distance_is_the_minimum_over_its_whole_path(seed):
    """min_distance is coal's minimum along the whole lift (0: the stick rests on its shelf at
    q[0]); certified_from and certified_min_distance say what the certificate proved."""
    (lift,) = run_fetch(seed, collision="coal", stages=("lift",))
    s = np.linspace(0.0, 1.0, 40)[:, None]
    dense = np.vstack([a + s * (b - a) for a, b in zip(lift.q[:-1], lift.q[1:], strict=True)])
    coal = gp.signed_distance(lift.scene, dense)
    assert lift.success and abs(lift.min_distance) <= RESTING
    assert f"never to penetrate by {1e6 * CONTACT_ALLOWANCE:.0f} µm" in lift.detail  # proven
    assert lift.min_distance == pytest.approx(coal.min(), abs=1e-9)
    summary = lift.summary()
    assert summary["certified_from"] == 1 and summary["certified_min_distance"] > 0
    assert coal[40:].min() >= summary["certified_min_distance"]
    grasp = run_fetch(seed, collision="coal", stages=("grasp",))[0].summary()
    assert grasp["certified_from"] is None and grasp["certified_min_distance"] is None
