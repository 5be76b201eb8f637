"""DiffCo refuses a scene it was not trained in (other obstacles), unless asked: the layout
rule, the explicit opt-in, active learning's new layout, and the paths that take a model."""

import numpy as np
import pytest
from hypothesis import assume, example, given, settings
from hypothesis import strategies as st

import gdnplan as gp
from gdnplan import metrics
from gdnplan.casadi_bridge import DistanceCallback
from gdnplan.errors import InputError
from gdnplan.models.diffco import DiffCo
from gdnplan.models.diffco_scene import LAYOUT_TOL, dataset_difference, layout_difference

SCENE_A = gp.make_scene("a")
Q = SCENE_A.robot.sample(16, seed=5)
REFUSED = r"trained among other obstacles.*model\.adapt\(scene\).*model\.ignoring_obstacles\(\)"


@pytest.fixture(scope="module")
def model():
    return DiffCo.train(SCENE_A, n=200, seed=0)


def moved(scene, j: int, dx: float, dy: float):
    """``scene`` with obstacle j translated by (dx, dy) (m); None when that is no valid scene."""
    polys = [p + (np.array([dx, dy]) if i == j else 0.0) for i, p in enumerate(scene.obstacles)]
    try:
        return scene.with_obstacles(polys)
    except InputError:
        return None


def entry_points(model, scene):
    return [
        lambda: model.distance(scene, Q),
        lambda: model.distance_and_grad(scene, Q),
        lambda: model.fitted().distance_and_grad(scene, Q),
        lambda: DistanceCallback("d", model, scene, 2),  # the planner's path (check_scene)
    ]


@settings(max_examples=25, deadline=None)
@given(
    dx=st.floats(-0.3, 0.3, allow_nan=False),
    dy=st.floats(-0.3, 0.3, allow_nan=False),
)
@example(dx=2 * LAYOUT_TOL, dy=0.0)  # just beyond the tolerance
@example(dx=0.0, dy=-0.01)
@example(dx=0.25, dy=0.25)
def test_a_moved_obstacle_is_refused_naming_the_fix(model, dx, dy):
    """Audit: a DiffCo trained in (a) scored any scene of its robot with (a)'s numbers."""
    assume(max(abs(dx), abs(dy)) > LAYOUT_TOL)
    scene = moved(SCENE_A, 0, dx, dy)
    assume(scene is not None)
    for call in entry_points(model, scene):
        with pytest.raises(InputError, match=REFUSED):
            call()


@settings(max_examples=10, deadline=None)
@given(dx=st.floats(-0.99 * LAYOUT_TOL, 0.99 * LAYOUT_TOL), dy=st.floats(-1e-7, 1e-7))
@example(dx=0.99 * LAYOUT_TOL, dy=-1e-7)  # 0.45 + 1e-6 − 0.45 rounds above 1e-6
def test_a_layout_within_the_tolerance_is_the_training_one(model, dx, dy):
    scene = moved(SCENE_A, 0, dx, dy)
    np.testing.assert_allclose(model.distance(scene, Q), model.distance(SCENE_A, Q), atol=1e-5)


def test_other_polygon_counts_and_vertex_lists_are_refused(model):
    square = SCENE_A.obstacles[0]
    others = [
        SCENE_A.with_obstacles([]),
        SCENE_A.with_obstacles([square, square + np.array([0.0, 0.6])]),
        SCENE_A.with_obstacles([np.roll(square, 1, axis=0)]),  # another first vertex
        gp.make_scene("b", seed=3),
    ]
    for scene in others:
        with pytest.raises(InputError, match=REFUSED):
            model.distance(scene, Q)


def test_float32_rounding_of_a_layout_is_within_the_rule():
    """A compact dataset stores float32 polygons: env c's 20 squares still match."""
    layout = gp.make_scene("c").obstacles
    rounded = [p.astype(np.float32).astype(float) for p in layout]
    assert layout_difference(tuple(layout), rounded) is None


def test_ignoring_obstacles_is_the_explicit_opt_in(model):
    scene = gp.make_scene("b", seed=3)
    stale = model.ignoring_obstacles()
    assert stale.ignore_obstacles and not model.ignore_obstacles  # a copy
    np.testing.assert_array_equal(stale.distance(scene, Q), model.distance(SCENE_A, Q))
    d, g = stale.fitted().distance_and_grad(scene, Q)
    d0, g0 = model.fitted().distance_and_grad(SCENE_A, Q)
    np.testing.assert_array_equal(d, d0)
    np.testing.assert_array_equal(g, g0)
    cb = DistanceCallback("d", stale, scene, 1)  # the planner's path takes it too
    np.testing.assert_allclose(np.asarray(cb(Q[0])).ravel(), model.distance(SCENE_A, Q[:1]))
    other = gp.Problem.from_toml("examples/three_link_arm.toml").scene
    with pytest.raises(InputError, match="trained for the planar2 robot"):
        stale.distance(other, np.zeros(3))  # the robot is still checked


def test_adapt_moves_the_record_to_the_new_scene(model):
    scene = gp.make_scene("b", seed=3)
    for start in (model, model.ignoring_obstacles()):
        adapted = start.adapt(scene, n_explore=40, seed=0, max_iter=200)
        assert not adapted.ignore_obstacles  # for its scene: checked again
        adapted.distance(scene, Q)
        adapted.fitted().distance_and_grad(scene, Q)
        with pytest.raises(InputError, match=REFUSED):
            adapted.distance(SCENE_A, Q)  # the old layout is stale now


def test_the_record_is_a_copy_of_the_training_scene(model):
    polys = [p.copy() for p in SCENE_A.obstacles]
    scene = SCENE_A.with_obstacles(polys)
    trained = DiffCo.train(scene, n=40, seed=0, max_iter=50)
    if scene.obstacles[0].flags.writeable:
        scene.obstacles[0][0, 0] += 0.05  # the caller edits its scene in place
        with pytest.raises(InputError, match=REFUSED):
            trained.distance(scene, Q)
    assert not trained.obstacles[0].flags.writeable
    trained.distance(SCENE_A, Q)


def test_a_diffco_built_without_a_layout_refuses_unless_asked(model):
    bare = DiffCo(model.kernel, model.support, model.alpha, model.pool, model.pool_d)
    with pytest.raises(InputError, match="does not record the obstacles"):
        bare.distance(SCENE_A, Q)
    np.testing.assert_array_equal(
        bare.ignoring_obstacles().distance(SCENE_A, Q), model.distance(SCENE_A, Q)
    )
    parts = (model.kernel, model.support, model.alpha, model.pool, model.pool_d)
    rebuilt = DiffCo(*parts, obstacles=SCENE_A.obstacles)
    np.testing.assert_array_equal(rebuilt.distance(SCENE_A, Q), model.distance(SCENE_A, Q))
    for field, bad in (("obstacles", [np.zeros(3)]), ("ignore_obstacles", 1)):
        with pytest.raises(InputError, match=f"^{field}: expected"):
            DiffCo(*parts, **{field: bad})


def test_predict_dataset_checks_every_sample(model):
    """Table I's batched path: the fixed scene passes, a random env's samples need the
    opt-in (the paper's "DiffCo w/o AL" row)."""
    own = metrics.test_set("a", 12)
    d, _ = metrics.predict(model, own, grad=False)
    np.testing.assert_allclose(d, model.distance(SCENE_A, own.q), atol=1e-12)
    random = metrics.test_set("b", 12)
    with pytest.raises(InputError, match=r"^dataset sample \d+: .*" + REFUSED[:20]):
        metrics.predict(model, random, grad=False)
    d, g = metrics.predict(model.ignoring_obstacles(), random, grad=True)
    assert d.shape == (12,) and g.shape == (12, 2)
    mixed = own.subset(np.arange(12))
    obstacles = mixed.obstacles.copy()
    obstacles[7, 0, :4] += 0.01
    assert dataset_difference(model.obstacles, obstacles, mixed.sizes)[0] == 7
    obstacles[7, 0, 0] = np.nan
    assert dataset_difference(model.obstacles, obstacles, mixed.sizes)[0] == 7
