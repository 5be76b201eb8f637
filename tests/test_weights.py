import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import torch

from gdnplan.errors import InputError
from gdnplan.models.weights import (
    TENSORS_HASH,
    card_path,
    file_sha256,
    read_card,
    read_weights,
    seal,
    write_weights,
)

WEIGHTS = Path(__file__).resolve().parent.parent / "weights"


def test_round_trip_leaves_no_temporary_files(tmp_path):
    tensors = {"w": torch.arange(6.0).reshape(2, 3).t(), "b": torch.ones(2)}  # w not contiguous
    given = {"model": "x", "v": 1.5}
    path = write_weights(tmp_path / "sub" / "net.safetensors", tensors, given)
    loaded, card = read_weights(path)
    assert card == {**given, TENSORS_HASH: file_sha256(path)} and TENSORS_HASH not in given
    assert card_path(path).name == "net.json"
    assert set(loaded) == {"w", "b"} and torch.equal(loaded["w"], tensors["w"])
    assert sorted(p.name for p in path.parent.iterdir()) == ["net.json", "net.safetensors"]


def test_missing_files_are_input_errors(tmp_path):
    path = write_weights(tmp_path / "net.safetensors", {"w": torch.zeros(1)}, {})
    card_path(path).unlink()
    with pytest.raises(InputError, match=r"--init: no card net\.json"):
        read_card(path, "--init")
    with pytest.raises(InputError, match="not found"):
        read_weights(tmp_path / "other.safetensors")


def test_a_save_interrupted_between_the_two_renames_is_never_used(tmp_path, monkeypatch):
    """New tensors beside the old card (the card's rename never happened) are refused."""
    import gdnplan.models.weights as w

    path = write_weights(tmp_path / "net.safetensors", {"w": torch.zeros(3)}, {"v": "old"})

    def killed(*args):
        raise KeyboardInterrupt

    monkeypatch.setattr(w, "write_json", killed)
    with pytest.raises(KeyboardInterrupt):
        write_weights(path, {"w": torch.ones(3)}, {"v": "new"})
    assert json.loads(card_path(path).read_text())["v"] == "old"  # the tensors are new
    with pytest.raises(InputError, match=r"card net\.json does not belong to net\.safetensors"):
        read_weights(path)
    with pytest.raises(InputError, match="does not belong"):
        read_card(path)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["net.json", "net.safetensors"]


def test_a_process_killed_between_the_writes_leaves_no_usable_mixed_pair(tmp_path):
    """os._exit right after the tensors' rename, in a real process: the pair is refused."""
    path = tmp_path / "net.safetensors"
    write_weights(path, {"w": torch.zeros(3)}, {"v": "old"})
    code = (
        "import os, torch\n"
        "import gdnplan.models.weights as w\n"
        "w.write_json = lambda *a: os._exit(9)\n"
        f"w.write_weights({str(path)!r}, {{'w': torch.ones(3)}}, {{'v': 'new'}})\n"
    )
    assert subprocess.run([sys.executable, "-c", code]).returncode == 9
    with pytest.raises(InputError, match="does not belong"):
        read_weights(path)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["net.json", "net.safetensors"]


def test_mixed_and_unsealed_pairs_are_refused(tmp_path):
    a = write_weights(tmp_path / "a.safetensors", {"w": torch.zeros(2)}, {"v": "a"})
    b = write_weights(tmp_path / "b.safetensors", {"w": torch.ones(2)}, {"v": "b"})
    card_path(b).write_text(card_path(a).read_text())  # a's card beside b's tensors
    with pytest.raises(InputError, match=r"model: card b\.json does not belong"):
        read_card(b, "model")
    card = json.loads(card_path(a).read_text())
    del card[TENSORS_HASH]
    card_path(a).write_text(json.dumps(card))
    with pytest.raises(InputError, match=r"records no 'tensors_sha256'.*seal"):
        read_weights(a)
    assert seal(a) == file_sha256(a)
    assert read_weights(a)[1]["v"] == "a"


def test_every_shipped_pair_is_sealed_and_verified():
    pairs = sorted(WEIGHTS.glob("*.safetensors"))
    assert len(pairs) >= 10
    for path in pairs:
        assert read_card(path)[TENSORS_HASH] == file_sha256(path), path.name


# ---------------------------------------------------------------- hostile weights (issue 19)
import io  # noqa: E402
import pickle  # noqa: E402
import shutil  # noqa: E402
from pathlib import Path  # noqa: E402

from hypothesis import HealthCheck, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

import gdnplan as gp  # noqa: E402
from gdnplan.errors import GdnplanError  # noqa: E402

WEIGHTS = Path(__file__).resolve().parent.parent / "weights"


def _pair(tmp_path: Path, name: str, tensors: bytes | None = None, card: str | None = None,
          src: str = "a") -> Path:  # fmt: skip
    """A weights pair in tmp_path: a copy of the shipped ``src`` pair with either file replaced,
    sealed (a card that is a JSON object records the tensors' hash), so the checks behind the
    pair check are reached."""
    path = tmp_path / f"{name}.safetensors"
    if tensors is None:
        shutil.copy(WEIGHTS / f"{src}.safetensors", path)
    else:
        path.write_bytes(tensors)
    text = (WEIGHTS / f"{src}.json").read_text() if card is None else card
    try:
        content = json.loads(text)
    except ValueError:
        content = None
    if isinstance(content, dict):
        text = json.dumps(content | {TENSORS_HASH: file_sha256(path)})
    card_path(path).write_text(text)
    return path


def _torch_save() -> bytes:
    buffer = io.BytesIO()
    torch.save({"w": torch.zeros(3)}, buffer)
    return buffer.getvalue()


def _card(**changes) -> str:
    card = json.loads((WEIGHTS / "a.json").read_text())
    return json.dumps(card | changes)


def _config(**changes) -> str:
    card = json.loads((WEIGHTS / "a.json").read_text())
    return json.dumps(card | {"config": card["config"] | changes})


def _nan_tensors() -> bytes:
    from safetensors.torch import load_file, save

    tensors = load_file(WEIGHTS / "a.safetensors")
    return save({k: torch.full_like(v, float("nan")) for k, v in tensors.items()})


def _tensors_as(dtype: torch.dtype, src: str = "a") -> bytes:
    """The shipped tensors of ``src`` cast to ``dtype`` (load_state_dict cast them back
    silently: int truncated every weight, complex dropped the imaginary part)."""
    from safetensors.torch import load_file, save

    tensors = load_file(WEIGHTS / f"{src}.safetensors")
    return save({k: (v + 0.5j if dtype.is_complex else v).to(dtype) for k, v in tensors.items()})


HOSTILE_WEIGHTS = {
    "truncated": lambda: {"tensors": (WEIGHTS / "a.safetensors").read_bytes()[:5000]},
    "header_only": lambda: {"tensors": (WEIGHTS / "a.safetensors").read_bytes()[:8]},
    "empty": lambda: {"tensors": b""},
    "pickle": lambda: {"tensors": pickle.dumps({"w": [1.0]})},
    "torch_save": lambda: {"tensors": _torch_save()},
    "all_nan": lambda: {"tensors": _nan_tensors()},
    "card_malformed": lambda: {"card": "{not json"},
    "card_list": lambda: {"card": "[1, 2]"},
    "card_not_utf8": lambda: {"card": "\udcff"},
    "card_no_config": lambda: {"card": json.dumps({"model": "graphdistnet"})},
    "card_config_list": lambda: {"card": _card(config=[1, 2])},
    "card_unknown_model": lambda: {"card": _card(model="svm")},
    "card_of_clearancenet": lambda: {"card": (WEIGHTS / "clearancenet_a.json").read_text()},
    "tensors_of_clearancenet": lambda: {
        "tensors": (WEIGHTS / "clearancenet_a.safetensors").read_bytes()
    },
    "wrong_shapes": lambda: {"card": _config(hidden=64)},
    "huge_layers": lambda: {"card": _config(layers=10**9)},
    "huge_hidden": lambda: {"card": _config(hidden=10**12)},
    "bad_tau": lambda: {"card": _config(tau=-1.0)},
    "nan_scale": lambda: {"card": _config(scale=float("nan"))},
    "mlp_int": lambda: {"card": _config(mlp=5)},
    "int64_tensors": lambda: {"tensors": _tensors_as(torch.int64)},
    "int8_tensors": lambda: {"tensors": _tensors_as(torch.int8)},
    "bool_tensors": lambda: {"tensors": _tensors_as(torch.bool)},
    "complex_tensors": lambda: {"tensors": _tensors_as(torch.complex64)},
    "clearancenet_int_tensors": lambda: {
        "tensors": _tensors_as(torch.int32, "clearancenet_a"),
        "card": (WEIGHTS / "clearancenet_a.json").read_text(),
    },
    "3d_int_tensors": lambda: {
        "tensors": _tensors_as(torch.int32, "ur5e_boxes3d_preliminary"),
        "card": (WEIGHTS / "ur5e_boxes3d_preliminary.json").read_text(),
    },
}


@pytest.mark.parametrize("name", HOSTILE_WEIGHTS)
def test_hostile_weights_files_are_gdnplan_errors_naming_the_file(name, tmp_path):
    parts = HOSTILE_WEIGHTS[name]()
    if parts.get("card") == "\udcff":
        path = _pair(tmp_path, name)
        card_path(path).write_bytes(b"\xff\xfe{")
    else:
        path = _pair(tmp_path, name, **parts)
    with pytest.raises(GdnplanError, match=name):
        gp.load_model(path)


def test_weights_for_another_robot_raise_before_use():
    """(a)'s planar2 weights on a planar7 scene and (d)'s on a planar2 one; ClearanceNet of the
    fixed layout (a) on a (b) scene. Same robot, other layout: GraphDistNet is used (its obstacle
    graph is an input; models/checks.py has the measurements)."""
    for weights, scene in (
        ("a", "d"),
        ("d", "a"),
        ("clearancenet_a", "b"),
        ("clearancenet_d", "a"),
    ):
        model = gp.load_model(WEIGHTS / f"{weights}.safetensors")
        s = gp.make_scene(scene, seed=1)
        with pytest.raises(GdnplanError, match="weights"):
            model.distance(s, s.robot.sample(2, seed=0))
    model, s = gp.load_model(WEIGHTS / "a.safetensors"), gp.make_scene("b", seed=1)
    assert np.isfinite(model.distance(s, s.robot.sample(2, seed=0))).all()


JSON = st.recursive(
    st.none() | st.booleans() | st.integers(-(10**12), 10**12) | st.floats() | st.text(max_size=5),
    lambda children: (
        st.lists(children, max_size=3) | st.dictionaries(st.text(max_size=5), children, max_size=3)
    ),
    max_leaves=6,
)


@settings(
    max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(
    where=st.sampled_from(["card", "config"]),
    key=st.sampled_from(["model", "config", "robot", "env", "layers", "hidden", "mlp", "readout",
                         "activation", "cross", "cross_k", "tau", "scale", "origin", "max_edge",
                         "min_readout", "node_distance", "probe_split", "correction_band"]),
    value=JSON,
)  # fmt: skip
def test_mutated_cards_load_or_raise_gdnplan_errors(where, key, value, tmp_path):
    """Any one field of a card (or of its config) replaced by any JSON value: the weights load
    or a GdnplanError says why (never another exception; sizes are checked on the meta device,
    so a huge network costs nothing). Inference is not run here; tests/test_weights_cards.py
    runs it on every card that loads (run-time sizes such as cross_k and probe_split are
    bounded by the config's checks)."""
    card = json.loads((WEIGHTS / "a.json").read_text())
    if where == "card":
        card[key] = value
    elif isinstance(card.get("config"), dict):
        card["config"][key] = value
    path = _pair(tmp_path, "mutated", card=json.dumps(card))
    try:
        gp.load_model(path)
    except GdnplanError:
        pass
