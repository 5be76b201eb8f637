"""GraphDistNet: gradients, determinism, invariances, continuity, shipped weights, bad input."""

from pathlib import Path

import numpy as np
import pytest
import torch
from shapely.geometry import Point, Polygon

import gdnplan as gp
from gdnplan.data import load
from gdnplan.graph import obstacle_graph, robot_graph, scene_obstacles
from gdnplan.models.graphdistnet import (
    GraphDistNet,
    GraphDistNetConfig,
    GraphDistNetModel,
    _pairwise_d2,
    _repeat,
    nearest_columns,
    nearest_obstacle_nodes,
    signed_ring_distance,
)
from gdnplan.train import GraphDistNetLoss, distance_loss, evaluate, gradient_loss

ROOT = Path(__file__).resolve().parent.parent
WEIGHTS = ROOT / "weights"
TEST_DATA = Path(__file__).resolve().parent / "data"

# metrics of the shipped weights on the committed 300-sample test splits must stay within these
SHIPPED = {  # env: (max MAE m, min AUC, max ACD); measured: results/table1.md, docs/notebook/
    "a": (0.025, 0.99, 0.06),
    "b": (0.02, 0.99, 0.25),
    "c": (0.035, 0.99, 0.3),
    "d": (0.03, 0.99, 0.45),
    "e": (0.045, 0.98, 0.45),
}


def random_model(
    env: str, dtype=torch.float32, keep_init: bool = False, **changes
) -> tuple[gp.Scene, GraphDistNetModel]:
    scene = gp.make_scene(env, seed=5)
    torch.manual_seed(0)
    config = GraphDistNetConfig.smooth(scale=scene.robot.reach, **changes)
    net = GraphDistNet(config)
    if config.min_readout and not keep_init:  # a readout MLP that is not yet zero
        torch.nn.init.normal_(net.head[-1].weight, std=0.3)
    return scene, GraphDistNetModel(net, dtype=dtype)


def test_batch_equals_per_sample_and_is_deterministic():
    scene, model = random_model("d")
    q = scene.robot.sample(6, seed=3)
    d_batch = model.distance(scene, q)
    d_single = np.array([model.distance(scene, qi)[0] for qi in q])
    np.testing.assert_allclose(d_batch, d_single, atol=1e-6)
    np.testing.assert_array_equal(d_batch, model.distance(scene, q))
    _, g1 = model.distance_and_grad(scene, q)
    _, g2 = model.distance_and_grad(scene, q)
    np.testing.assert_array_equal(g1, g2)


@pytest.mark.parametrize("changes", [{}, {"two_way": False}])
def test_deferred_gradient_equals_distance_and_grad(changes):
    scene, model = random_model("d", **changes)
    model.chunk = 4  # several chunks, each holding its graph until the gradient is asked for
    q = scene.robot.sample(10, seed=6)
    d, grad = model.distance_deferred_grad(scene, q)
    d_ref, g_ref = model.distance_and_grad(scene, q)
    np.testing.assert_array_equal(d, d_ref)
    np.testing.assert_allclose(grad(), g_ref, rtol=1e-6, atol=1e-7)
    np.testing.assert_array_equal(grad(), grad())  # asked twice: the same array, one backward


def test_permuting_obstacles_and_start_vertices_keeps_distance():
    scene, model = random_model("e")
    q = scene.robot.sample(5, seed=4)
    rng = np.random.default_rng(0)
    shuffled = [np.roll(scene.obstacles[i], rng.integers(1, 5), 0) for i in rng.permutation(5)]
    d = model.distance(scene, q)
    np.testing.assert_allclose(model.distance(scene.with_obstacles(shuffled), q), d, atol=1e-5)


@pytest.mark.parametrize("env", ["d", "e"])  # overlapping squares; non-convex α-shapes
def test_signed_ring_distance_matches_shapely(env):
    scene = gp.make_scene(env, seed=4)
    graph = obstacle_graph(*scene_obstacles([scene]), dtype=torch.float64)
    rng = np.random.default_rng(0)
    lo, hi = graph.nodes[0].min(0).values.numpy(), graph.nodes[0].max(0).values.numpy()
    points = rng.uniform(lo - 0.1, hi + 0.1, (400, 2))
    s = signed_ring_distance(torch.tensor(points)[None], graph.nodes, graph.next, graph.mask)[0]
    polygons = [Polygon(p) for p in scene.obstacles]
    for x, got in zip(points, s.numpy(), strict=True):
        pt = Point(x)
        edge = min(p.exterior.distance(pt) for p in polygons)
        inside = any(p.contains(pt) for p in polygons)
        assert got == pytest.approx(-edge if inside else edge, abs=1e-9)
    assert (s < 0).any() and (s > 0).any()


def test_signed_ring_distance_gradient_matches_finite_differences():
    """∂s/∂points and ∂s/∂nodes (through the nearest edge only) against central differences,
    outside and inside the rings, batch of 2 against shared (1, M) rings."""
    scene = gp.make_scene("d", seed=4)
    graph = obstacle_graph(*scene_obstacles([scene]), dtype=torch.float64)
    rng = np.random.default_rng(1)
    lo, hi = graph.nodes[0].min(0).values.numpy(), graph.nodes[0].max(0).values.numpy()
    points = torch.tensor(rng.uniform(lo, hi, (2, 60, 2)), requires_grad=True)
    nodes = graph.nodes.clone().requires_grad_(True)

    def f(p, n):
        return signed_ring_distance(p, n, graph.next, graph.mask)

    assert torch.autograd.gradcheck(f, (points, nodes), eps=1e-7, atol=1e-6)
    s = f(points, nodes)
    assert (s < 0).any() and (s > 0).any()


def test_lean_first_layer_equals_naive_per_edge_reference():
    torch.manual_seed(1)
    scene, model = random_model("b")
    net = model.net
    q = scene.robot.sample(4, seed=0)
    robot = robot_graph(scene.robot).batch(robot_graph(scene.robot).positions(q))
    polys, sizes = scene_obstacles([scene] * 4)
    g = net.union(robot, obstacle_graph(polys, sizes))
    idx, w = net.cross_weights(g, None, 0, net.candidates(g), None)
    h = torch.randn(*g.x0.shape[:2], net.config.hidden)
    for k, z in ((0, g.x0), (1, torch.cat([g.x0, h], -1))):
        lean = net.edge_preactivation(k, z, g.nbr, idx, w)
        b = z.shape[0]
        z_j = torch.stack([z[torch.arange(b)[:, None], g.nbr[..., e]] for e in range(3)], 2)
        z_c = z[torch.arange(b)[:, None, None], idx]  # (B, N, C, D)
        z_bar = (w[..., None] * z_c).sum(2)
        feat = torch.cat([z_j - z[:, :, None], (z_bar - z)[:, :, None].expand(-1, -1, 3, -1)], -1)
        naive = net.convs[k][0](feat)
        torch.testing.assert_close(lean, naive, atol=1e-5, rtol=1e-5)


def test_sparse_nearest_nodes_equal_dense_selection_and_gradient():
    gen = torch.Generator().manual_seed(0)
    xr = torch.rand(6, 9, 2, generator=gen, dtype=torch.float64, requires_grad=True)
    xo = torch.rand(30, 2, generator=gen, dtype=torch.float64)
    weights = torch.rand(6, 9, 5, generator=gen, dtype=torch.float64)
    dense = nearest_columns(_pairwise_d2(xr, xo), 5)
    sparse = nearest_obstacle_nodes(xr, xo, 5)
    for a, b in zip(dense, sparse, strict=True):
        torch.testing.assert_close(a, b, rtol=0, atol=0)
    grads = [
        torch.autograd.grad((weights * (near + log_phi)).sum(), xr)[0]
        for _, log_phi, near in (dense, sparse)
    ]
    torch.testing.assert_close(grads[0], grads[1], rtol=1e-12, atol=1e-12)


def reference_distance_and_grad(
    model: GraphDistNetModel, scene: gp.Scene, q: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """d̂ and ∂d̂/∂q by the padded :meth:`GraphDistNet.forward` and the node Jacobians."""
    graph = robot_graph(scene.robot)
    obstacles = obstacle_graph(*scene_obstacles([scene]), None, dtype=model.dtype)
    nodes, jac = graph.positions_and_jacobians(q)
    x = torch.tensor(nodes, dtype=model.dtype, requires_grad=True)
    d = model.net(graph.batch(x, dtype=model.dtype), _repeat(obstacles, len(q)))
    (dx,) = torch.autograd.grad(d.sum(), x)
    return d.detach().double().numpy(), np.einsum("bni,bnij->bj", dx.double().numpy(), jac)


LEAN_CASES = [  # (env, weights or config changes): small obstacle graphs pad the candidates
    ("a", "a"),
    ("e", "e"),
    ("fetch", "ur5e"),
    ("b", {"cross_k": 2}),
    ("d", {"mlp": ()}),
    ("d", {"two_way": False}),  # obstacle features cached per scene
    ("a", {"two_way": False}),  # fewer obstacle nodes than candidates
    ("c", {"node_distance": True}),
    ("d", {"node_distance": True, "two_way": False}),
    ("e", {"node_distance": True, "two_way": False, "min_readout": True}),
    ("b", {"node_distance": True, "min_readout": True}),
    ("a", {"node_distance": True, "min_readout": True, "correction_band": 0.05, "tau_min": 0.01}),
    ("a", {"node_distance": True, "min_readout": True, "correction_band": 0.05, "probe_split": 4}),
    ("d", {"node_distance": True, "min_readout": True, "two_way": False, "probe_split": 3}),
]


@pytest.mark.parametrize(("env", "net"), LEAN_CASES)
def test_lean_inference_equals_reference_forward(env, net):
    if isinstance(net, str):
        model, scene = shipped(net), gp.make_scene(env, seed=3)
    else:
        scene, model = random_model(env, **net)
    model.chunk = 32
    q = scene.robot.sample(70, seed=1)  # three chunks
    d_ref, g_ref = reference_distance_and_grad(model, scene, q)
    d, g = model.distance_and_grad(scene, q)
    scale = np.abs(g_ref).max()
    np.testing.assert_allclose(d, d_ref, atol=2e-6 * model.config.scale)
    np.testing.assert_allclose(g, g_ref, atol=1e-4 * scale)
    np.testing.assert_allclose(model.distance(scene, q), d, atol=2e-6 * model.config.scale)


def test_scene_cache_follows_the_scene_object():
    scene, model = random_model("e")
    other = gp.make_scene("e", seed=6)
    q = scene.robot.sample(8, seed=0)
    d = model.distance(scene, q)
    d_other = model.distance(other, q)
    _, fresh = random_model("e")
    np.testing.assert_array_equal(d_other, fresh.distance(other, q))
    assert np.abs(d - d_other).min() > 1e-5
    np.testing.assert_array_equal(model.distance(scene, q), d)


def sweep_jumps(model, scene: gp.Scene, joints: list[int], n: int = 200) -> np.ndarray:
    """Largest |Δd̂| (m) between consecutive 0.003 rad steps along sweeps of each joint."""
    robot = scene.robot
    q0 = robot.sample(1, seed=7)[0]
    out = []
    for j in joints:
        q = np.repeat(q0[None], n, 0)
        q[:, j] = np.clip(q0[j] - 0.3 + 0.003 * np.arange(n), robot.lower[j], robot.upper[j])
        out.append(np.abs(np.diff(model.distance(scene, q))).max())
    return np.array(out)


def shipped(name: str) -> GraphDistNetModel:
    path = WEIGHTS / f"{name}.safetensors"
    if not path.exists():
        pytest.skip(f"{path.name} not trained yet")
    return gp.load_model(path)


@pytest.mark.parametrize("env", ["b", "d"])
def test_shipped_default_is_continuous_along_joint_sweeps(env):
    model = shipped(env)
    assert model.config.cross == "soft_knn"
    scene = gp.make_scene(env, seed=11)
    assert sweep_jumps(model, scene, list(range(scene.robot.dof))[:3]).max() < 0.01


@pytest.mark.xfail(reason="expected finding: the paper's random/argmax partners make d̂ jump")
def test_faithful_variant_jumps_along_joint_sweeps():
    model = shipped("b_faithful")
    scene = gp.make_scene("b", seed=11)
    assert sweep_jumps(model, scene, [0, 1]).max() < 0.01


@pytest.mark.parametrize("env", sorted(SHIPPED))
def test_shipped_weights_on_committed_test_split(env):
    model = shipped(env)
    m = evaluate(model.net, load(TEST_DATA / f"{env}_test.npz"))
    max_mae, min_auc, max_acd = SHIPPED[env]
    assert m["mae_m"] <= max_mae and m["auc"] >= min_auc and m["acd"] <= max_acd, m


def test_bad_inputs_raise_input_error():
    scene, model = random_model("a")
    with pytest.raises(gp.InputError):
        model.distance(scene, np.zeros((2, 3)))
    with pytest.raises(gp.InputError):
        model.distance_and_grad(scene, np.array([np.nan, 0.0]))
    with pytest.raises(gp.InputError):
        model.distance(scene.with_obstacles([]), np.zeros(2))
    with pytest.raises(gp.InputError):
        GraphDistNetConfig(cross="nearest")
    with pytest.raises(gp.InputError, match="min_readout needs node_distance"):
        GraphDistNetConfig(min_readout=True)
    with pytest.raises(gp.InputError, match="tau_min"):
        GraphDistNetConfig(node_distance=True, min_readout=True, tau_min=0.0)
    with pytest.raises(gp.InputError, match="correction_band"):
        GraphDistNetConfig(node_distance=True, correction_band=0.02)  # without min_readout
    with pytest.raises(gp.InputError, match="correction_band"):
        GraphDistNetConfig(node_distance=True, min_readout=True, correction_band=-0.02)
    with pytest.raises(gp.InputError, match="probe_split"):
        GraphDistNetConfig(node_distance=True, probe_split=3)  # without min_readout
    with pytest.raises(gp.InputError):
        GraphDistNetConfig.from_dict({"layers": 2, "width": 3})
    with pytest.raises(gp.InputError):
        gp.load_model(WEIGHTS / "nonexistent.safetensors")


def test_node_distance_warm_start_keeps_the_loaded_function(tmp_path):
    from safetensors.torch import save_file

    from gdnplan.train import _load_init

    scene, old = random_model("c")
    path = tmp_path / "old.safetensors"
    save_file(old.net.state_dict(), str(path))
    new = GraphDistNet(old.config.with_(node_distance=True))
    _load_init(new, path)
    q = scene.robot.sample(20, seed=1)
    # one code path for both (the compiled whole pass serves the old network only)
    d_old = GraphDistNetModel(old.net, fused=False).distance(scene, q)
    np.testing.assert_array_equal(GraphDistNetModel(new, fused=False).distance(scene, q), d_old)
    assert not torch.any(new.distance_in)
    new.distance_in.data.fill_(0.5)  # the feature then changes d̂
    assert np.abs(GraphDistNetModel(new).distance(scene, q) - d_old).max() > 1e-4
    with pytest.raises(gp.InputError, match="does not fit"):  # another readout MLP
        _load_init(GraphDistNet(new.config.with_(min_readout=True)), path)


def test_min_readout_starts_at_the_soft_minimum_of_node_distances():
    """An untrained min_readout network is m: between apart polygons about coal's distance."""
    scene, model = random_model(
        "c", torch.float64, keep_init=True, node_distance=True, min_readout=True
    )
    q = scene.robot.sample(300, seed=2)
    d = gp.CoalModel().distance(scene, q)
    free = d > 0.05
    err = np.abs(model.distance(scene, q) - d)[free]
    tau = model.config.tau_min * model.config.scale
    assert free.sum() > 50 and err.max() < tau * np.log(60)  # soft-min bias ≤ τ log N


def test_probe_points_find_links_crossing_the_square():
    """(a)'s links can cross the square with no vertex inside the other polygon: the soft
    minimum over the vertices misses those overlaps, the one over edge points does not."""
    scene = gp.make_scene("a")
    q = scene.robot.sample(3000, seed=4)
    f = gp.CoalModel().distance(scene, q)
    m = {}
    for split in (1, 5):
        _, model = random_model(
            "a",
            torch.float64,
            keep_init=True,
            node_distance=True,
            min_readout=True,
            probe_split=split,
            tau_min=1e-4,
        )
        m[split] = model.distance(scene, q)
    deep = f < -0.01
    assert (m[1][deep] > 0).sum() >= 5  # vertices only: overlaps taken for free space
    assert (m[5][deep] < 0).all()
    free = f > 0.01
    np.testing.assert_allclose(m[5][free], f[free], atol=1e-3)  # still the distance when apart


def test_correction_band_warm_start_keeps_the_loaded_estimate_in_overlap(tmp_path):
    from safetensors.torch import save_file

    from gdnplan.train import _load_init

    scene, old = random_model("a", torch.float64, node_distance=True)
    path = tmp_path / "old.safetensors"
    save_file(old.net.state_dict(), str(path))
    config = old.config.with_(min_readout=True, correction_band=0.01, probe_split=5, tau_min=1e-4)
    new = GraphDistNet(config)
    _load_init(new, path)
    q = scene.robot.sample(3000, seed=4)
    f = gp.CoalModel().distance(scene, q)
    d_old, d_new = (
        old.distance(scene, q),
        GraphDistNetModel(new, dtype=torch.float64).distance(scene, q),
    )
    overlap = f < -0.01
    np.testing.assert_allclose(d_new[overlap], d_old[overlap], atol=1e-3 * np.abs(d_old).max())
    free = f > 0.05
    np.testing.assert_allclose(d_new[free], f[free], atol=1e-3)  # m: the distance itself


def test_correction_band_leaves_the_soft_minimum_away_from_contact():
    """With a trained-looking (non-zero) readout MLP, the banded network equals the bare soft
    minimum m once m > 2β (gate < 3e-4) and differs from it in overlap."""
    band = 0.02
    scene, gated = random_model(
        "c", torch.float64, node_distance=True, min_readout=True, correction_band=band
    )
    bare = GraphDistNet(gated.config)
    bare.load_state_dict(gated.net.state_dict())
    torch.nn.init.zeros_(bare.head[-1].weight)
    torch.nn.init.zeros_(bare.head[-1].bias)
    q = scene.robot.sample(400, seed=2)
    m = GraphDistNetModel(bare, dtype=torch.float64).distance(scene, q)
    d = gated.distance(scene, q)
    far, overlap = m > 3 * band, m < 0
    assert far.sum() > 50 and overlap.sum() > 10
    assert np.abs(d - m)[far].max() < 1e-3 * np.abs(d - m)[overlap].mean()


@pytest.mark.parametrize(
    "readout", [{}, {"min_readout": True}, {"min_readout": True, "correction_band": 0.02}]
)
def test_training_step_with_gradient_loss_has_finite_gradients(readout):
    """The gradient loss differentiates ∂d̂/∂q once more: every readout must survive it."""
    from gdnplan.train import forward_with_grad, tensors

    ds = load(TEST_DATA / "a_test.npz")
    config = GraphDistNetConfig.smooth(scale=1.2, node_distance=True, **readout)
    weights = GraphDistNetLoss(grad_weight=0.1, grad_norm_weight=0.1)
    torch.manual_seed(0)
    net = GraphDistNet(config)
    t = tensors(ds)
    rows = torch.arange(64)
    robot, obstacles = t.batch(rows, "cpu")
    d, g = forward_with_grad(net, robot, obstacles, t.jac[rows], True)
    loss = distance_loss(d, t.d[rows], weights, 1.2) + gradient_loss(g, t.grad[rows], weights, 1.2)
    loss.backward()
    assert all(torch.isfinite(p.grad).all() for p in net.parameters() if p.grad is not None)


def test_config_keeps_the_architecture_and_refuses_removed_options_at_other_values():
    """Old flat cards: loss weights skipped, removed options at their default dropped; a
    removed option at another value, or a loss weight given to the architecture, is refused."""
    old = {"layers": 2, "activation": "leaky_relu", "max_edge": None, "grad_weight": 0.1}
    assert GraphDistNetConfig.from_dict(old) == GraphDistNetConfig(layers=2)
    for key, value in (("activation", "silu"), ("max_edge", 0.25)):
        with pytest.raises(gp.InputError, match=rf"^config: {key} = .*was removed"):
            GraphDistNetConfig.from_dict({key: value})
    with pytest.raises(gp.InputError, match="GraphDistNetLoss"):
        GraphDistNetConfig().with_(grad_weight=0.1)


def test_faithful_first_layer_picks_one_random_partner_per_graph():
    """§IV-A: "a single connection node per graph (j_{c,r}, j_{c,o})", randomly selected."""
    scene = gp.make_scene("d", seed=2)
    net = GraphDistNet(GraphDistNetConfig.faithful(scale=scene.robot.reach))
    graph = robot_graph(scene.robot)
    obstacles = obstacle_graph(*scene_obstacles([scene]), None)
    nodes = torch.tensor(graph.positions_and_jacobians(scene.robot.sample(3, seed=0))[0])
    g = net.union(graph.batch(nodes), _repeat(obstacles, 3))
    idx = net.partners_argmax(g, None, 0, torch.Generator().manual_seed(1))
    n_r = g.n_robot
    assert idx.shape == g.mask.shape
    assert (idx[:, :n_r] >= n_r).all() and (idx[:, n_r:] < n_r).all()  # the other graph
    assert g.mask.gather(1, idx).all()  # real nodes only
    distinct = [len(set(row[:n_r].tolist())) for row in idx] + [
        len(set(row[n_r:][g.mask[i, n_r:]].tolist())) for i, row in enumerate(idx)
    ]
    assert max(distinct) == 1
    assert len({int(row[0]) for row in idx}) > 1  # a new draw per sample


def test_paper_architecture_cards_name_their_draw_and_old_per_node_cards_are_refused():
    config = GraphDistNetConfig.faithful()
    assert config.to_dict()["random_pick"] == "graph"
    assert GraphDistNetConfig.from_dict(config.to_dict()) == config
    assert "random_pick" not in GraphDistNetConfig().to_dict()  # soft partners draw nothing
    with pytest.raises(gp.InputError, match=r"one per node.*retrain"):
        GraphDistNetConfig.from_dict({"cross": "argmax"})  # cards before the per-graph draw
    with pytest.raises(gp.InputError, match=r"random_pick = 'node'.*was removed"):
        GraphDistNetConfig.from_dict({"cross": "argmax", "random_pick": "node"})
