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


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"name": ""}, "name: expected a CasADi name"),
        ({"name": "a b"}, "name: expected a CasADi name"),
        ({"name": None}, "name: expected a CasADi name"),
        ({"model": None}, "model: expected a distance model"),
        ({"model": "coal"}, "model: expected a distance model"),
        ({"scene": None}, "scene: expected"),
        ({"n_points": -1}, r"n_points: expected an integer in \[1, "),
        ({"n_points": 10**9}, r"n_points: expected an integer in \[1, "),
        ({"n_points": 2.7}, "n_points"),
        ({"per_link": "yes"}, "per_link: expected True or False"),
        ({"cap": float("nan")}, "cap: expected a number > 0"),
        ({"cap": -1.0}, "cap: expected a number > 0"),
        ({"cap": "x"}, "cap: expected a number > 0"),
    ],
)
def test_bad_callback_arguments_are_input_errors_before_casadi(kwargs, match):
    """CasADi's own errors (bad_alloc, RuntimeError with a printed traceback) or silently wrong
    rows (a cap of −1 made every constraint −1) before; now one InputError naming the field."""
    args = {"name": "d", "model": gp.CoalModel(), "scene": gp.make_scene("a"), "n_points": 3}
    args.update(kwargs)
    with pytest.raises(gp.InputError, match=match):
        DistanceCallback(**args)


def test_a_model_for_another_robot_is_refused_when_the_callback_is_built():
    model = gp.load_model("d")
    with pytest.raises(gp.InputError):
        DistanceCallback("d", model, gp.make_scene("b"), 3)


def test_a_non_finite_trial_point_gives_nan_rows_for_ipopt_to_backtrack():
    scene = gp.make_scene("a")
    cb = DistanceCallback("d", gp.CoalModel(), scene, 2)
    f, jac = _functions(cb, 4)
    x = np.r_[scene.robot.sample(1, seed=0).ravel(), np.nan, 0.0]
    assert np.all(np.isnan(np.array(f(x))))
    assert np.all(np.isnan(np.array(jac(x).nonzeros())))  # structural zeros stay 0
    assert cb.model_calls == 0
    good = scene.robot.sample(2, seed=1).ravel()
    np.testing.assert_allclose(
        np.array(f(good)).ravel(), gp.signed_distance(scene, good.reshape(2, 2))
    )
