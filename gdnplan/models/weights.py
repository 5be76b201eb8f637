"""Weights files: tensors in ``<name>.safetensors`` and a JSON card beside them, ``<name>.json``.

The card says what the tensors are (``"model"``: ``"graphdistnet"`` / ``"clearancenet"``, the
architecture's ``"config"``) and where they came from (data, seed, training log, test metrics,
git commit). Both files are written atomically (a temporary file, then ``os.replace``), so an
interrupted save leaves the previous pair intact.
"""

from __future__ import annotations

import json
import os
from pathlib import Path

import torch
from safetensors.torch import save_file

from ..errors import InputError
from .checks import load_tensors, parse_card


def card_path(path: Path | str) -> Path:
    """The card beside the weights ``path``: the same name with the suffix ``.json``."""
    return Path(path).with_suffix(".json")


def read_card(path: Path | str, what: str = "weights") -> dict:
    """The JSON card of the weights ``path``; InputError (prefixed by ``what``) when missing."""
    card = card_path(path)
    if not card.exists():
        raise InputError(f"{what}: no card {card.name} beside {path}")
    return parse_card(card, what)


def read_weights(path: Path | str) -> tuple[dict[str, torch.Tensor], dict]:
    """Tensors and card of the weights ``path``; InputError when either file is missing."""
    path = Path(path)
    if not path.exists():
        raise InputError(f"weights: {path} not found")
    card = read_card(path)
    return load_tensors(path), card


def write_json(path: Path | str, obj: dict) -> None:
    """Write ``obj`` as indented JSON to ``path`` atomically (numpy scalars as floats)."""
    path = Path(path)
    tmp = path.with_name(path.name + ".tmp")
    tmp.write_text(json.dumps(obj, indent=2, default=float))
    os.replace(tmp, path)


def write_tensors(path: Path | str, tensors: dict[str, torch.Tensor]) -> None:
    """Write ``tensors`` to the safetensors file ``path`` atomically."""
    path = Path(path)
    tmp = path.with_name(path.name + ".tmp")
    save_file({k: v.contiguous() for k, v in tensors.items()}, str(tmp))
    os.replace(tmp, path)


def write_weights(path: Path | str, tensors: dict[str, torch.Tensor], card: dict) -> Path:
    """Write the weights ``path`` and its card (directories created); returns ``path``."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    write_tensors(path, tensors)
    write_json(card_path(path), card)
    return path
