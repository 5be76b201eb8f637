"""Weights cards whose ``config`` is edited (the tensors' hash still matches, so the pair is
read): every field is checked for its type and range (gdnplan.models.fields), a config that
disagrees with the tensors is refused before anything runs, and a card that loads gives finite
distances and gradients. Every refusal is an InputError naming the card file and the field."""

from __future__ import annotations

import json
import math
import shutil
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st

import gdnplan as gp
from gdnplan.arm3d import load_robot3d, random_boxes
from gdnplan.models.weights import card_path

WEIGHTS = Path(__file__).resolve().parent.parent / "weights"
SCENES = {  # a weights file -> a scene of the robot it was trained for (memoised below)
    "a": lambda: gp.make_scene("b", seed=1),  # two-way, probe points, correction band
    "d": lambda: gp.make_scene("d", seed=1),  # one-way, node distances
    "a_faithful": lambda: gp.make_scene("a"),  # the paper's argmax network
    "clearancenet_b": lambda: gp.make_scene("b", seed=1),
    "ur5e_boxes3d_preliminary": lambda: random_boxes(load_robot3d("ur5e"), 20, seed=0),
}
_SCENES: dict = {}


def scene_of(name: str):
    if name not in _SCENES:
        _SCENES[name] = SCENES[name]()
    return _SCENES[name]


def mutated(tmp_path: Path, src: str, **changes) -> Path:
    """A copy of the shipped pair ``src`` as ``mutated.safetensors`` with config ``changes``."""
    path = tmp_path / "mutated.safetensors"
    shutil.copy(WEIGHTS / f"{src}.safetensors", path)
    card = json.loads((WEIGHTS / f"{src}.json").read_text())
    card["config"] = card["config"] | changes
    card_path(path).write_text(json.dumps(card))
    return path


def assert_finite(model, scene) -> None:
    """Distances and gradients of a few configurations are finite."""
    robot = scene.robot
    q = np.random.default_rng(2).uniform(robot.lower, robot.upper, (3, robot.dof))
    d = model.distance(scene, q)
    d2, g = model.distance_and_grad(scene, q)
    assert d.shape == (3,) and np.isfinite(d).all() and np.isfinite(d2).all(), d
    assert np.isfinite(g).all(), g


# ------------------------------------------------------------------ the audit's cards
AUDIT = [
    ("scale", 1e-300),
    ("scale", 1e300),
    ("scale", True),
    ("scale", 0),
    ("origin", [1e300, 0]),
    ("origin", "ab"),
    ("origin", [0.0]),
    ("origin", [[0, 0]]),
    ("origin", [0.0, float("nan")]),
    ("cross_k", 2.5),
    ("cross_k", 10**9),
    ("probe_split", 1.5),
    ("probe_split", 10**9),
    ("two_way", "yes"),
    ("two_way", 1),
    ("node_distance", "false"),
    ("min_readout", 0),
    ("layers", 4.0),
    ("hidden", True),
    ("mlp", [32.0, 32, 32]),
    ("mlp", [[32], 32, 32]),
    ("readout", "32"),
    ("tau", -1),
    ("tau_min", 1e300),
    ("correction_band", 1e-300),
    ("correction_band", "0.01"),
    ("cross", 1),
]


@pytest.mark.parametrize(("key", "value"), AUDIT, ids=[f"{k}={v!r}"[:30] for k, v in AUDIT])
def test_audited_graphdistnet_configs_are_input_errors_naming_card_and_field(key, value, tmp_path):
    with pytest.raises(gp.InputError, match=rf"mutated\.json.*{key}"):
        gp.load_model(mutated(tmp_path, "a", **{key: value}))


@pytest.mark.parametrize(
    ("src", "key", "value"),
    [
        ("ur5e_boxes3d_preliminary", "scale", 1e-300),
        ("ur5e_boxes3d_preliminary", "length", 1e300),
        ("ur5e_boxes3d_preliminary", "origin", [0.0, 0.0]),
        ("ur5e_boxes3d_preliminary", "rim", 10**9),
        ("ur5e_boxes3d_preliminary", "cross_k", 2.5),
        ("ur5e_boxes3d_preliminary", "min_readout", "false"),
        ("ur5e_boxes3d_preliminary", "hidden", 32.0),
        ("clearancenet_b", "scale", 1e-300),
        ("clearancenet_b", "dof", True),
        ("clearancenet_b", "n_vertices", 4.0),
        ("clearancenet_b", "hidden", [256, 256.5, 256]),
        ("clearancenet_b", "dropout", float("nan")),
        ("clearancenet_b", "encoding", ["pose"]),
        ("clearancenet_b", "env", 3),
    ],
)
def test_audited_3d_and_clearancenet_configs_are_input_errors(src, key, value, tmp_path):
    with pytest.raises(gp.InputError, match=rf"mutated\.json.*{key}"):
        gp.load_model(mutated(tmp_path, src, **{key: value}))


@pytest.mark.parametrize(
    ("src", "changes"),
    [
        ("a", {"hidden": 16}),
        ("a", {"layers": 3}),
        ("a", {"mlp": [32, 32]}),
        ("a", {"readout": [32]}),
        ("a", {"node_distance": False, "min_readout": False, "probe_split": 1}),
        ("d", {"min_readout": False}),
        ("a_faithful", {"node_distance": True}),
        ("ur5e_boxes3d_preliminary", {"hidden": 16}),
        ("ur5e_boxes3d_preliminary", {"layers": 5}),
        ("ur5e_boxes3d_preliminary", {"min_readout": True}),
        ("ur5e_boxes3d_preliminary", {"readout": [32, 32]}),
        ("clearancenet_b", {"hidden": [128, 128, 128]}),
        ("clearancenet_b", {"n_obstacles": 2}),
        ("clearancenet_b", {"encoding": "vertices"}),
    ],
)
def test_a_config_that_disagrees_with_its_tensors_is_refused_before_use(src, changes, tmp_path):
    with pytest.raises(gp.InputError, match=r"mutated\.json"):
        gp.load_model(mutated(tmp_path, src, **changes))


@pytest.mark.parametrize(
    ("src", "changes"),
    [
        ("a", {"scale": 1e-3}),
        ("a", {"scale": 1e3}),
        ("a", {"origin": [1e3, -1e3]}),
        ("a", {"cross_k": 64, "probe_split": 32}),
        ("d", {"cross_k": 64, "two_way": True}),
        ("ur5e_boxes3d_preliminary", {"cross_k": 64, "rim": 3}),
        ("ur5e_boxes3d_preliminary", {"scale": 1e-3, "length": 1e3}),
        ("clearancenet_b", {"scale": 1e3, "dropout": 0.0, "n_vertices": 1024}),
    ],
)
def test_configs_at_the_bounds_load_and_give_finite_distances(src, changes, tmp_path):
    assert_finite(gp.load_model(mutated(tmp_path, src, **changes)), scene_of(src))


# ------------------------------------------------------------------ any one field, any value
HOSTILE = st.sampled_from(
    [None, True, False, 0, -1, 1.5, 2.0, math.nan, math.inf, -math.inf, 1e300, -1e300, 1e-300,
     -1e-300, 10**9, 10**30, 2**63, -(2**63), "", "yes", "false", "soft_knn", "pose", [], [0.0],
     [[0, 0]], [1e300, 0.0], [0.0, 0.0], [0.0, 0.0, 0.0], [1, 2], [True, False], ["a", "b"],
     [16, 16, 16], {"x": 1}]
)  # fmt: skip
NEAR = (  # values of the right type, in range or just outside it
    st.integers(-2, 70)
    | st.floats(1e-4, 2e3)
    | st.floats(-2e3, 2e3)
    | st.lists(st.integers(-1, 40), max_size=4)
    | st.lists(st.floats(-2e3, 2e3), min_size=2, max_size=3)
)
ANY = st.recursive(
    st.none() | st.booleans() | st.integers() | st.floats() | st.text(max_size=4),
    lambda children: st.lists(children, max_size=3),
    max_leaves=5,
)


@settings(
    max_examples=200,
    deadline=None,
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
)
@given(data=st.data(), src=st.sampled_from(sorted(SCENES)))
def test_one_mutated_config_field_is_an_input_error_or_finite(data, src, tmp_path):
    """Any one field of a card's config replaced by a value of the wrong type, out of range or
    in range: loading raises InputError, or the model's distances and gradients on a few
    configurations of a scene of its robot are finite."""
    config = json.loads((WEIGHTS / f"{src}.json").read_text())["config"]
    key = data.draw(st.sampled_from(sorted(config)), label="key")
    value = data.draw(HOSTILE | NEAR | ANY, label="value")
    try:
        model = gp.load_model(mutated(tmp_path, src, **{key: value}))
    except gp.InputError as e:
        assert "mutated.json" in str(e)
        event("refused")
        return
    event("loaded")
    assert_finite(model, scene_of(src))


IN_RANGE = {  # fields that leave the tensors' shapes alone -> values of their documented range
    "scale": st.floats(1e-3, 1e3),
    "length": st.floats(1e-3, 1e3),
    "origin": st.lists(st.floats(-1e3, 1e3), min_size=3, max_size=3),
    "cross_k": st.integers(1, 64),
    "probe_split": st.integers(1, 32),
    "tau": st.floats(1e-12, 1e6),
    "tau_min": st.floats(1e-12, 1e6),
    "correction_band": st.floats(1e-3, 1e3),
    "two_way": st.booleans(),
    "rim": st.integers(3, 64),
    "n_vertices": st.integers(1, 1024),
}


@settings(
    max_examples=60,
    deadline=None,
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
)
@given(data=st.data(), src=st.sampled_from(sorted(SCENES)))
def test_one_config_field_anywhere_in_its_range_gives_finite_distances(data, src, tmp_path):
    """A field that does not change the tensors' shapes, set anywhere in its documented range
    (origin: the first 2 or 3 coordinates): the model loads, or is refused for a combination
    (e.g. probe points without the soft-minimum readout), and its distances are finite."""
    config = json.loads((WEIGHTS / f"{src}.json").read_text())["config"]
    key = data.draw(st.sampled_from(sorted(set(config) & set(IN_RANGE))), label="key")
    value = data.draw(IN_RANGE[key], label="value")
    if key == "origin":
        value = value[: len(config["origin"])]
    try:
        model = gp.load_model(mutated(tmp_path, src, **{key: value}))
    except gp.InputError as e:
        assert "needs" in str(e), e  # a combination, not the range
        return
    assert_finite(model, scene_of(src))


# ------------------------------------------------------------------ names too long for the OS
LONG = ["a" * 5000, "a" * 5000 + ".safetensors", "x/" + "a" * 300 + ".safetensors"]


@pytest.mark.parametrize("ref", LONG, ids=["name", "file", "folder"])
def test_a_weights_name_too_long_for_the_file_system_is_an_input_error(ref):
    with pytest.raises(gp.InputError, match=r"^weights: ") as e:
        gp.load_model(ref)
    assert len(str(e.value)) < 400
    with pytest.raises(gp.InputError, match=r"^weights: "):
        gp.load_model(Path(ref))


def test_a_problem_name_too_long_for_the_file_system_is_a_gdnplan_error():
    with pytest.raises(gp.GdnplanError, match="problem"):
        gp.Problem.from_toml("a" * 5000)


@pytest.mark.parametrize("ref", LONG[:2], ids=["name", "file"])
def test_cli_weights_too_long_exit_2_naming_weights(ref, capsys):
    from gdnplan.cli import run

    with pytest.raises(SystemExit) as exit_:
        run(["plan", "planar2_square", "--weights", ref, "--quiet"])
    lines = capsys.readouterr().err.strip().splitlines()
    assert exit_.value.code == 2, lines
    assert len(lines) == 1 and lines[0].startswith("error: weights: "), lines
    assert "internal error" not in lines[0] and len(lines[0]) < 400


def test_values_in_messages_stay_one_short_line():
    from gdnplan.models.fields import shown

    nested: list = []
    for _ in range(10_000):
        nested = [nested]
    assert shown(10**5000) == "an integer of about 5000 digits"
    assert shown(nested) == "a list nested too deeply to show"
    assert shown("a" * 100) == "'" + "a" * 39 + "…"
