"""ClearanceNet: input layout, autograd gradients (its training: test_train_clearancenet.py)."""

import numpy as np

import gdnplan as gp
from gdnplan.data import pad_polygons
from gdnplan.models import clearancenet as cn


def test_pose_vector_is_invariant_to_quarter_turns_and_vertex_order():
    config = cn.ClearanceNetConfig.for_env("b")
    sq = gp.make_scene("b", seed=2).obstacles[0]
    a = cn.obstacle_vector(config, *pad_polygons([[sq]]))
    b = cn.obstacle_vector(config, *pad_polygons([[np.roll(sq, 1, 0)]]))
    np.testing.assert_allclose(a, b, atol=1e-12)
    np.testing.assert_allclose(a[0, :2], sq.mean(0))
    assert config.n_features == 2 + 4


def test_vertex_vector_layout_for_alpha_shapes():
    config = cn.ClearanceNetConfig.for_env("e")
    assert config.dropout == 0.5 and config.encoding == "vertices"
    scene = gp.make_scene("e", seed=1)
    v = cn.obstacle_vector(config, *pad_polygons([list(scene.obstacles)]))
    assert v.shape == (1, 5 * 15 * 2)
    first = scene.obstacles[0]
    np.testing.assert_allclose(v[0, : 2 * len(first)], first.ravel())


def test_views_of_any_stride_give_the_distances_of_a_copy():
    """torch.as_tensor refused a negative-stride q (ValueError from ClearanceNet's inference);
    the shared q check (robot_checks.as_batch) now returns a C-contiguous array."""
    scene = gp.make_scene("d", seed=3)
    q = scene.robot.sample(6, seed=0)
    for name in ("clearancenet_d", "d"):
        model = gp.load_model(name)
        for view in (q[::-1, ::-1], q[::2], np.asfortranarray(q)):
            d, g = model.distance_and_grad(scene, view)
            d_copy, g_copy = model.distance_and_grad(scene, view.copy())
            np.testing.assert_array_equal(d, d_copy)
            np.testing.assert_array_equal(g, g_copy)
