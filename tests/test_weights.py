import pytest
import torch

from gdnplan.errors import InputError
from gdnplan.models.weights import card_path, read_card, read_weights, write_weights


def test_round_trip_leaves_no_temporary_files(tmp_path):
    tensors = {"w": torch.arange(6.0).reshape(2, 3).t(), "b": torch.ones(2)}  # w not contiguous
    path = write_weights(tmp_path / "sub" / "net.safetensors", tensors, {"model": "x", "v": 1.5})
    loaded, card = read_weights(path)
    assert card == {"model": "x", "v": 1.5} and card_path(path).name == "net.json"
    assert set(loaded) == {"w", "b"} and torch.equal(loaded["w"], tensors["w"])
    assert sorted(p.name for p in path.parent.iterdir()) == ["net.json", "net.safetensors"]


def test_missing_files_are_input_errors(tmp_path):
    path = write_weights(tmp_path / "net.safetensors", {"w": torch.zeros(1)}, {})
    card_path(path).unlink()
    with pytest.raises(InputError, match=r"--init: no card net\.json"):
        read_card(path, "--init")
    with pytest.raises(InputError, match="not found"):
        read_weights(tmp_path / "other.safetensors")
