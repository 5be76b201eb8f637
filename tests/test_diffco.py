"""DiffCo: exact score gradients, classification of its own environment, active learning."""

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

import gdnplan as gp
from gdnplan.errors import InputError
from gdnplan.evaluate import roc_auc
from gdnplan.models.diffco import DiffCo, fastron


@pytest.fixture(scope="module")
def model_a():
    return DiffCo.train(gp.make_scene("a"), n=1500, seed=0)


def test_fastron_separates_training_points():
    x = np.linspace(-1, 1, 21)
    K = 1 / (1 + 10 * (x[:, None] - x[None]) ** 2) ** 2
    y = np.where(np.abs(x) < 0.3, 1.0, -1.0)
    alpha = fastron(K, y, np.zeros(21))
    assert np.all(np.sign(K @ alpha) == y)
    assert np.count_nonzero(alpha) < 21


def test_classifies_its_environment(model_a):
    scene = gp.make_scene("a")
    q = scene.robot.sample(2000, seed=7)
    f = gp.signed_distance(scene, q)
    assert roc_auc(-model_a.distance(scene, q), f <= 0) > 0.98
    assert not model_a.is_distance


def test_active_learning_improves_auc_on_changed_environment(model_a):
    """Trained on (a), tested on a (b) scene: near chance before, much better after."""
    scene = gp.make_scene("b", seed=3)
    q = scene.robot.sample(2000, seed=8)
    collide = gp.signed_distance(scene, q) <= 0
    before = roc_auc(-model_a.ignoring_obstacles().distance(scene, q), collide)
    after = roc_auc(-model_a.adapt(scene, seed=0).distance(scene, q), collide)
    assert after > before + 0.2 and after > 0.95


@pytest.mark.slow
def test_active_learning_7dof_c_to_d():
    model = DiffCo.train(gp.make_scene("c"), n=3000, seed=0)
    scene = gp.make_scene("d", seed=5)
    q = scene.robot.sample(2000, seed=8)
    collide = gp.signed_distance(scene, q) <= 0
    before = roc_auc(-model.ignoring_obstacles().distance(scene, q), collide)
    after = roc_auc(-model.adapt(scene, n_explore=2000, seed=0).distance(scene, q), collide)
    assert after > before + 0.1


def test_adapt_draws_as_before_the_seed_check(model_a):
    """adapt's pool is bit-identical to the pre-check code: one generator of ``seed`` draws the
    perturbations, then continues into the uniform exploration samples (regression: the
    seed check refused the generator and `reproduce table1` failed)."""
    scene = gp.make_scene("b", seed=3)
    robot = model_a.kernel.robot
    new = model_a.adapt(scene, n_explore=64, seed=4, max_iter=10)
    rng = np.random.default_rng(4)
    near = np.repeat(model_a.support, 2, 0)
    near = np.clip(near + rng.normal(0, 0.1, near.shape), robot.lower, robot.upper)
    explore = rng.uniform(robot.lower, robot.upper, size=(64, robot.dof))
    np.testing.assert_array_equal(new.pool, np.concatenate([model_a.support, near, explore]))
    again = model_a.adapt(scene, n_explore=64, seed=np.random.default_rng(4), max_iter=10)
    np.testing.assert_array_equal(again.pool, new.pool)


# ---------------------------------------------------------------- hostile inputs (audit)
@pytest.fixture(scope="module")
def fetch_diffco():
    return DiffCo.train(gp.make_scene("fetch"), n=60, seed=0)


def test_a_robot_of_the_same_joint_count_is_refused_not_evaluated(fetch_diffco):
    """Audit: DiffCo trained for the UR5e (3 planar joints) scored a three-link URDF arm's
    configurations with the UR5e's kinematics, silently; other robots are refused now."""
    other = gp.Problem.from_toml("examples/three_link_arm.toml").scene
    assert other.robot.dof == fetch_diffco.kernel.robot.dof
    for call in (
        lambda: fetch_diffco.distance(other, np.zeros(3)),
        lambda: fetch_diffco.fitted().distance_and_grad(other, np.zeros(3)),
        lambda: fetch_diffco.adapt(other, n_explore=5),
    ):
        with pytest.raises(InputError, match=r"trained for the ur5e robot.*three_link_arm"):
            call()
    fetch_diffco.distance(gp.make_scene("fetch"), np.zeros(3))  # its robot and scene: accepted


@settings(max_examples=8, deadline=None)
@given(b=st.integers(0, 3))
@example(b=0)
def test_every_batch_size_gives_arrays_of_that_size(fetch_diffco, b):
    """Audit: an empty batch (0, dof) raised numpy's reshape ValueError."""
    scene = gp.make_scene("fetch")
    q = scene.robot.sample(b, seed=1)
    for model in (fetch_diffco, fetch_diffco.fitted()):
        d, g = model.distance_and_grad(scene, q)
        assert d.shape == (b,) and g.shape == (b, 3) and model.distance(scene, q).shape == (b,)


@pytest.mark.parametrize(
    ("changes", "field"),
    [
        ({"n": 0}, "n"),  # argmin of an empty sequence
        ({"n": 10**6}, "n"),  # a 10¹² kernel matrix
        ({"gamma": float("nan")}, "gamma"),
        ({"gamma": -1.0}, "gamma"),  # every value inf
        ({"beta": float("nan")}, "beta"),  # NaN weights
        ({"margin": float("inf")}, "margin"),
        ({"max_iter": -1}, "max_iter"),  # no support point: 0 everywhere
    ],
)
def test_bad_training_settings_name_the_field(changes, field):
    with pytest.raises(InputError, match=rf"^{field}: expected"):
        DiffCo.train(gp.make_scene("fetch"), **{"n": 20, **changes})


@pytest.mark.parametrize(
    ("changes", "field"),
    [({"n_exploit": -1}, "n_exploit"), ({"sigma": -1.0}, "sigma"), ({"sigma": 1e300}, "sigma")],
)
def test_bad_active_learning_settings_name_the_field(fetch_diffco, changes, field):
    with pytest.raises(InputError, match=rf"^{field}: expected"):
        fetch_diffco.adapt(gp.make_scene("fetch", seed=1), **{"n_explore": 5, **changes})
