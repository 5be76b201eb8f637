"""Every learned model's distance entry points refuse what is no scene of their kind with an
InputError naming ``scene`` (not an AttributeError from inside), like the exact functions
(``gdnplan.scene.check_scene``)."""

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

import gdnplan as gp
from gdnplan.arm3d import Scene3D, load_robot3d
from gdnplan.errors import InputError

PLANAR = gp.make_scene("b", seed=0)
SPACE = Scene3D(load_robot3d("ur5e"), [])
WRONG = [None, "b", 5, np.zeros(3), object()]


def entries(model) -> list:
    names = [
        "distance",
        "distance_and_grad",
        "distance_deferred_grad",  # audit: GraphDistNet's raised AttributeError on None
        "learned_distance",
        "learned_distance_and_grad",
    ]
    return [getattr(model, n) for n in names if hasattr(model, n)]


@pytest.mark.parametrize("weights", ["b", "b_faithful", "clearancenet_b"])
@pytest.mark.parametrize("scene", [*WRONG, SPACE])
def test_planar_models_refuse_other_scenes(weights, scene):
    model = gp.load_model(weights)
    for entry in entries(model):
        with pytest.raises(InputError, match="scene"):
            entry(scene, np.zeros(2))


@pytest.mark.parametrize("scene", [*WRONG, PLANAR])
def test_3d_models_refuse_other_scenes(scene):
    model = gp.load_model("ur5e_boxes3d_preliminary")
    for entry in entries(model):
        with pytest.raises(InputError, match="scene"):
            entry(scene, np.zeros(6))


@pytest.mark.parametrize("scene", [*WRONG, SPACE])
def test_diffco_refuses_other_scenes(scene):
    from gdnplan.models.diffco import DiffCo

    model = DiffCo.train(gp.make_scene("a"), n=60, seed=0, max_iter=200)
    for entry in entries(model):
        with pytest.raises(InputError, match="scene"):
            entry(scene, np.zeros(2))


@pytest.mark.parametrize("weights", ["b", "b_faithful", "clearancenet_b"])
@settings(max_examples=6, deadline=None)
@given(b=st.integers(0, 40))
@example(b=0)
def test_every_batch_size_gives_arrays_of_that_size(weights, b):
    """Audit: ClearanceNet's empty batch (0, dof) raised numpy's 'need at least one array to
    concatenate'; every planar model now returns (0,) and (0, dof) as coal does."""
    model = gp.load_model(weights)
    q = PLANAR.robot.sample(b, seed=2)
    d, g = model.distance_and_grad(PLANAR, q)
    assert d.shape == (b,) and g.shape == (b, 2)
    assert model.distance(PLANAR, q).shape == (b,)
    if hasattr(model, "distance_deferred_grad"):
        d, grad = model.distance_deferred_grad(PLANAR, q)
        assert d.shape == (b,) and grad().shape == (b, 2)
