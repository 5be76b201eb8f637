"""A learned model's run settings: one InputError naming the setting for anything but what
the passes run, and the caller's network left as it was."""

from __future__ import annotations

import numpy as np
import pytest
import torch

import gdnplan as gp
from gdnplan.models.graphdistnet import GraphDistNetModel
from gdnplan.models.graphdistnet3d import GraphDistNet3DModel

BAD = [
    ({"dtype": torch.int32}, "dtype: expected torch.float32 or torch.float64"),
    ({"dtype": "float32"}, "dtype: expected"),
    ({"dtype": np.float32}, "dtype: expected"),
    ({"dtype": torch.float16}, "dtype: expected"),
    ({"chunk": 0}, r"chunk: expected an integer in \[1, "),
    ({"chunk": 1.5}, "chunk: expected an integer"),
    ({"fused": "yes"}, "fused: expected True, False or None"),
]


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [*BAD, ({"device": "meta"}, "device: expected"), ({"device": "bogus"}, "device: expected")],
)
def test_planar_model_settings_are_checked(kwargs, match):
    net = gp.load_model("d").net
    with pytest.raises(gp.InputError, match=match):
        GraphDistNetModel(net, **kwargs)


@pytest.mark.parametrize(
    ("kwargs", "match"), [*BAD, ({"self_collision": "no"}, "self_collision: expected True or")]
)
def test_3d_model_settings_are_checked(kwargs, match):
    net = gp.load_model("ur5e_boxes3d_preliminary").net
    with pytest.raises(gp.InputError, match=match):
        GraphDistNet3DModel(net, **kwargs)


def test_a_model_in_another_dtype_leaves_the_callers_network_as_it_was():
    """Module.to works in place: the first model failed on its next scene (dtype mismatch)."""
    first = gp.load_model("d")
    scene = gp.make_scene("d", seed=3)
    q = scene.robot.sample(4, seed=0)
    twin = GraphDistNetModel(first.net, first.card, dtype=torch.float64)
    assert next(first.net.parameters()).dtype == torch.float32
    assert next(twin.net.parameters()).dtype == torch.float64
    np.testing.assert_allclose(first.distance(scene, q), twin.distance(scene, q), atol=1e-4)
    same = GraphDistNetModel(first.net, first.card)
    assert same.net is first.net  # nothing to change: no copy


SET_LATER = [
    ("threads", 0, "threads: expected an integer"),
    ("threads", -1, "threads: expected an integer"),
    ("threads", 2.5, "threads: expected an integer"),
    ("threads", "2", "threads: expected an integer"),
    ("threads", True, "threads: expected an integer"),
    ("chunk", 0, "chunk: expected an integer"),
    ("chunk", "8", "chunk: expected an integer"),
    ("fused", "yes", "fused: expected True, False or None"),
    ("dtype", torch.float64, "dtype: fixed when the model is made"),
]


def _models():
    """One model of each learned kind (planar GraphDistNet, ClearanceNet, GraphDistNet-3D)."""
    return [gp.load_model(name) for name in ("d", "clearancenet_b", "ur5e_boxes3d_preliminary")]


@pytest.mark.parametrize(("attr", "bad", "match"), SET_LATER, ids=repr)
def test_a_setting_changed_after_construction_is_checked_as_at_construction(attr, bad, match):
    for model in _models():
        if not hasattr(model, attr):
            continue  # ClearanceNet has no fused pass
        before = getattr(model, attr)
        with pytest.raises(gp.InputError, match=match):
            setattr(model, attr, bad)
        assert getattr(model, attr) == before


def test_3d_settings_changed_later_are_checked_and_take_effect():
    model = gp.load_model("ur5e_boxes3d_preliminary")
    for attr, bad in (("self_collision", "no"), ("contact_offset", float("nan"))):
        with pytest.raises(gp.InputError, match=attr):
            setattr(model, attr, bad)


def test_fused_changed_after_a_call_changes_the_pass():
    model = gp.load_model("d")
    scene = gp.make_scene("d", seed=0)
    q = scene.robot.sample(4, seed=0)
    model.fused = True
    fast = model.distance(scene, q)
    model.fused = False  # the scene's cached compiled pass is dropped, not kept
    assert model._graphs(scene).whole is None
    np.testing.assert_allclose(model.distance(scene, q), fast, atol=1e-5)
