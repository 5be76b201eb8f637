from pathlib import Path

import casadi
import numpy as np
import pytest
from test_gradients import SmoothModel  # the stand-in model of the callback gradient tests

import gdnplan as gp
from gdnplan.casadi_bridge import DistanceCallback


def _functions(cb, size):
    x = casadi.MX.sym("x", size)
    y = cb(x)
    return casadi.Function("f", [x], [y]), casadi.Function("J", [x], [casadi.jacobian(y, x)])


def test_value_and_jacobian_at_one_point_cost_one_model_call():
    scene = gp.make_scene("a")
    cb = DistanceCallback("d", gp.CoalModel(), scene, 3)
    f, jac = _functions(cb, 6)
    x = scene.robot.sample(3, seed=0).ravel()
    d = np.array(f(x)).ravel()
    jac(x)
    assert cb.model_calls == 1
    np.testing.assert_allclose(d, gp.signed_distance(scene, x.reshape(3, 2)))


def test_shape_mismatch_raises_input_error():
    scene = gp.make_scene("a")
    cb = DistanceCallback("d", gp.CoalModel(), scene, 3)
    with pytest.raises(gp.InputError, match="x: expected 3·2"):
        cb.evaluate(np.zeros(5))


WEIGHTS_A = Path(__file__).resolve().parent.parent / "weights" / "a.safetensors"


@pytest.mark.skipif(not WEIGHTS_A.exists(), reason="no GraphDistNet weights for env a")
def test_values_alone_skip_the_backward_pass_of_a_deferred_model():
    scene = gp.make_scene("a")
    cb = DistanceCallback("d", gp.load_model(WEIGHTS_A), scene, 3)
    f, jac = _functions(cb, 6)
    x = scene.robot.sample(3, seed=0).ravel()
    f(x)  # a line-search trial point: the value only
    f(x + 0.01)
    assert (cb.model_calls, cb.gradient_calls) == (2, 0)
    jac(x + 0.01)  # accepted: the Jacobian at the cached point costs the backward pass only
    assert (cb.model_calls, cb.gradient_calls) == (2, 1)


def test_per_link_on_a_model_without_it_raises():
    scene = gp.make_scene("a")
    with pytest.raises(gp.InputError, match="per_link"):
        DistanceCallback("d", SmoothModel(2), scene, 3, per_link=True)
