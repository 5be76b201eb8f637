"""ClearanceNet's training loop: a short fit beats a constant and survives a safetensors round
trip."""

import numpy as np
import pytest

import gdnplan as gp
from gdnplan.data import make_shard
from gdnplan.evaluate import predict
from gdnplan.models import clearancenet as cn
from gdnplan.train import FitConfig, train_clearancenet


def test_short_training_beats_constant_and_round_trips(tmp_path):
    ds = make_shard("b", 0, 0, 1500)
    model = train_clearancenet(
        "b", ds, cn.ClearanceNetConfig.for_env("b", hidden=(64, 64)), FitConfig(epochs=15)
    )
    test = make_shard("b", 1, 0, 300)
    d, g = predict(model, test, grad=True)
    assert np.mean(np.abs(d - test.d)) < 0.8 * np.mean(np.abs(test.d - np.median(ds.d)))
    path = model.save(tmp_path / "cn.safetensors")
    again = gp.load_model(path)
    assert isinstance(again, cn.ClearanceNetModel)
    d2, g2 = predict(again, test, grad=True)
    np.testing.assert_allclose(d2, d)
    np.testing.assert_allclose(g2, g)
    scene = test.scene(0)
    assert again.distance(scene, test.q[:1])[0] == pytest.approx(d[0], abs=1e-6)


def test_old_module_and_keywords_still_work_with_a_deprecation_warning():
    from gdnplan.train_clearancenet import train

    ds = make_shard("b", 0, 0, 40)
    config = cn.ClearanceNetConfig.for_env("b", hidden=(8,))
    with pytest.warns(DeprecationWarning, match="FitConfig"):
        model = train("b", ds, config, epochs=2, batch=8)
    assert model.card["training"]["epochs"] == 2 and model.card["training"]["batch"] == 8
