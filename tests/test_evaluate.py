"""Table I metrics against hand-computed cases, and one model evaluated end to end."""

import numpy as np
import pytest
from scipy import stats

import gdnplan as gp
from gdnplan import evaluate as ev
from gdnplan.data import make_shard


def test_mae_of_known_errors():
    assert ev.mean_absolute_error(np.array([0.1, -0.2, 0.5]), np.array([0.0, 0.0, 0.2])) == (
        pytest.approx((0.1 + 0.2 + 0.3) / 3)
    )
    with pytest.raises(gp.InputError):
        ev.mean_absolute_error(np.zeros(3), np.zeros(2))


def test_welch_p_value_matches_hand_computation():
    a = np.array([0.12, 0.30, 0.25, 0.08, 0.41, 0.22])
    b = np.array([0.05, 0.07, 0.02, 0.11, 0.04, 0.06, 0.09, 0.03])
    va, vb = a.var(ddof=1) / len(a), b.var(ddof=1) / len(b)
    t = (a.mean() - b.mean()) / np.sqrt(va + vb)
    nu = (va + vb) ** 2 / (va**2 / (len(a) - 1) + vb**2 / (len(b) - 1))
    p = 2 * stats.t.sf(abs(t), nu)
    assert ev.welch_p_value(a, b) == pytest.approx(p, rel=1e-12)
    assert ev.welch_p_value(a, b) < 0.05


def test_auc_against_known_roc_with_ties():
    # positives score 3, 2, 2; negatives 2, 1. Pairs (pos > neg) count 1, ties ½:
    # 3 beats both (2), each 2 ties one and beats one (2 × 1.5) -> 5 / 6.
    score = np.array([3.0, 2.0, 2.0, 2.0, 1.0])
    pos = np.array([True, True, True, False, False])
    assert ev.roc_auc(score, pos) == pytest.approx(5 / 6)
    fpr, tpr = ev.roc_curve(score, pos)
    np.testing.assert_allclose(fpr, [0, 0, 0.5, 1])
    np.testing.assert_allclose(tpr, [0, 1 / 3, 1, 1])
    assert np.trapezoid(tpr, fpr) == pytest.approx(5 / 6)
    assert ev.roc_auc(np.arange(4.0), np.array([False, False, True, True])) == 1.0
    assert ev.roc_auc(np.arange(4.0), np.array([True, True, False, False])) == 0.0
    assert np.isnan(ev.roc_auc(np.arange(3.0), np.ones(3, bool)))


def test_cosine_distance_of_known_vectors():
    g = np.array([[1.0, 0.0], [0.0, 2.0], [1.0, 1.0], [0.0, 0.0], [3.0, 0.0]])
    ref = np.array([[2.0, 0.0], [0.0, -1.0], [1.0, 0.0], [1.0, 0.0], [0.0, 0.0]])
    np.testing.assert_allclose(
        ev.cosine_distances(g, ref), [0.0, 2.0, 1 - np.sqrt(0.5), 1.0, 1.0], atol=1e-12
    )
    cd = ev.used_cosine_distances(g, ref)  # the zero coal gradient is left out
    assert len(cd) == 4
    assert np.mean(cd) == pytest.approx((0 + 2 + 1 - np.sqrt(0.5) + 1) / 4)


def test_acd_and_its_standard_error_of_one_flipped_gradient():
    """One of n gradients reversed: cosine distances (2, 0, …, 0), so the ACD is 2/n and its
    standard error √(s² / n) with s² = (4 − n (2/n)²) / (n − 1) = 4/n is 2/n too."""
    ds = make_shard("a", 1, 0, 50)
    g_hat = ds.grad.copy()
    g_hat[0] *= -1
    res = ev.evaluate_predictions("flipped", ds, ds.d, g_hat, 0.1, True, 1.2)
    n = int((np.linalg.norm(ds.grad, axis=1) > 0).sum())
    assert res.n_grad == n > 40 and np.linalg.norm(ds.grad[0]) > 0
    assert res.acd == pytest.approx(2 / n) and res.acd_se == pytest.approx(2 / n)


def test_timed_returns_result_and_positive_time():
    out, seconds = ev.timed(lambda: sum(range(1000)), repeats=3)
    assert out == 499500 and 0 < seconds < float("inf")  # a duration, not a timing bound


def test_coal_scores_perfectly_on_random_env():
    ds = make_shard("b", 1, 0, 60)
    assert len(ev.scene_groups(ds)) == 60
    res = ev.evaluate_model(gp.CoalModel(), "b", n=60, n_grad=30, ds=ds)
    assert res.mae == pytest.approx(0, abs=1e-12) and res.acd == pytest.approx(0, abs=1e-9)
    assert res.auc == 1.0 and res.n_grad == 30 and res.seconds > 0


def test_reproduce_table1_fast_writes_markdown(tmp_path):
    from typer.testing import CliRunner

    from gdnplan.cli import app

    out = tmp_path / "t.md"
    res = CliRunner().invoke(
        app, ["reproduce", "table1", "--fast", "--envs", "a", "--out", str(out)]
    )
    assert res.exit_code == 0, res.output
    text = out.read_text()
    assert "| a | coal |" in text and "| a | DiffCo |" in text and "machine:" in text
    assert "| a | GraphDistNet (gdnplan) | " in text  # beside the paper's row, named
    faithful = "| a | GraphDistNet (paper architecture, this implementation) | "
    trained = (ev.WEIGHTS_DIR / "a_faithful.safetensors").exists()
    assert (faithful + "not trained yet |" in text) != trained and faithful in text
    assert "| a | GraphDistNet (paper architecture, mean of 8 first-layer draws) | " in text
    assert "- (a) GraphDistNet (gdnplan): soft nearest-node partners" in text  # its network


def test_network_line_names_the_architecture_and_loss():
    card = {
        "config": {"cross": "argmax", "random_pick": "graph", "two_way": True},
        "training": {"loss": {"grad_weight": 0.1}, "seconds": 12.0},
        "data": {"n_train": 36000, "extra": {}},
    }
    line = ev.network_line(card)
    assert line.startswith("random (one per graph), then argmax partners, two-way cross edges;")
    assert "loss: distance + gradient λ = 0.1; 36 000 training samples; 12 s" in line
    assert "layers of" not in line  # the default size goes unsaid
    small = {**card, "config": {"layers": 2, "hidden": 16, "mlp": [16, 16], "readout": [16]}}
    assert ev.network_line(small).startswith(
        "soft nearest-node partners, two-way cross edges, 2 layers of 16 features;"
    )


def test_fig5_panels_and_detour_path_is_free():
    scene = gp.make_scene("a")
    path = ev.detour_path(scene, np.array([1.3, 1.5]), np.array([1.3, -2.6]))
    assert gp.signed_distance(scene, path).min() > 0
    fig = ev.fig5("a", grid=11, diffco_train=200)
    has_gdn = (ev.WEIGHTS_DIR / "a.safetensors").exists()
    assert len(fig.axes) == 3 + has_gdn


def test_roc_and_scatter_figures(tmp_path):
    ds = make_shard("a", 1, 0, 50)
    rows = [
        ev.Result("coal", "a", 50, 0.1, None, None, float("nan"), None, None, 0, None, ds.d),
        ev.evaluate_predictions("noisy", ds, ds.d + 0.01, None, 0.1, True, 1.2),
    ]
    paths = ev.table1_figures({"a": (rows, None)}, tmp_path)
    assert all(p.stat().st_size > 1000 for p in paths)


def test_one_name_per_loader_and_the_old_names_warn():
    """By environment name (Table I) vs by file: distinct names; the old shared name of both
    still works, with a DeprecationWarning naming the new one."""
    from gdnplan.assets import weights_file
    from gdnplan.models.graphdistnet import load_graphdistnet, load_graphdistnet_weights

    scene = gp.make_scene("a", seed=0)
    q = scene.robot.sample(4, seed=0)
    by_env = ev.graphdistnet_of_env("a")
    by_file = load_graphdistnet_weights(weights_file("a"))
    np.testing.assert_array_equal(by_env.distance(scene, q), by_file.distance(scene, q))
    assert ev.graphdistnet_of_env("zz") is None and ev.clearancenet_of_env("zz") is None
    with pytest.warns(DeprecationWarning, match="graphdistnet_of_env"):
        assert ev.load_graphdistnet("a") is not None
    with pytest.warns(DeprecationWarning, match="clearancenet_of_env"):
        assert ev.load_clearancenet("a") is not None
    with pytest.warns(DeprecationWarning, match="load_graphdistnet_weights"):
        load_graphdistnet(weights_file("a"))


def test_mean_of_draws_is_the_mean_of_single_draws():
    """The mean-of-draws row: d̂ and ∂d̂/∂q averaged over generator seeds 0 … R − 1; one draw is
    seed 0's; the draws differ (the first layer is random); soft-partner networks refuse."""
    from gdnplan.env_models import BatchedGraphDistNet
    from gdnplan.train import predict, tensors

    model = gp.load_model(ev.WEIGHTS_DIR / "b_faithful.safetensors")
    ds = make_shard("b", 1, 0, 40)
    t = tensors(ds)
    runs = [predict(model.net, t, grad=True, seed=r) for r in range(3)]
    d3, g3 = BatchedGraphDistNet(model, draws=3).predict_dataset(ds, grad=True)
    np.testing.assert_allclose(d3, np.mean([r[0] for r in runs], 0), rtol=1e-12)
    np.testing.assert_allclose(g3, np.mean([r[1] for r in runs], 0), rtol=1e-12)
    d1, g1 = BatchedGraphDistNet(model).predict_dataset(ds, grad=False)
    np.testing.assert_array_equal(d1, runs[0][0])
    assert g1 is None and np.abs(runs[1][0] - runs[0][0]).max() > 1e-4
    for bad in (0, -1, 2.0, True):
        with pytest.raises(gp.InputError, match="draws"):
            BatchedGraphDistNet(model, draws=bad)
    with pytest.raises(gp.InputError, match="argmax"):
        BatchedGraphDistNet(gp.load_model("b"), draws=2)
    for other in (None, gp.CoalModel(), gp.load_model("clearancenet_d")):
        with pytest.raises(gp.InputError, match="model: expected a planar GraphDistNet"):
            BatchedGraphDistNet(other)
