"""DiffCo: exact score gradients, classification of its own environment, active learning."""

import numpy as np
import pytest

import gdnplan as gp
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
    before = roc_auc(-model_a.distance(scene, q), collide)
    after = roc_auc(-model_a.adapt(scene, seed=0).distance(scene, q), collide)
    assert after > before + 0.2 and after > 0.95


@pytest.mark.slow
def test_active_learning_7dof_c_to_d():
    model = DiffCo.train(gp.make_scene("c"), n=3000, seed=0)
    scene = gp.make_scene("d", seed=5)
    q = scene.robot.sample(2000, seed=8)
    collide = gp.signed_distance(scene, q) <= 0
    before = roc_auc(-model.distance(scene, q), collide)
    after = roc_auc(-model.adapt(scene, n_explore=2000, seed=0).distance(scene, q), collide)
    assert after > before + 0.1
