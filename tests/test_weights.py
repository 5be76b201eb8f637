import json
import subprocess
import sys
from pathlib import Path

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
