"""Weights files: tensors in ``<name>.safetensors`` and a JSON card beside them, ``<name>.json``.

The card says what the tensors are (``"model"``: ``"graphdistnet"`` / ``"clearancenet"``, the
architecture's ``"config"``) and where they came from (data, seed, training log, test metrics,
git commit). Training checkpoints are pairs of the same kind (tensors + the loop's state).

A pair is used together or not at all. The two files are written one after the other, each
atomically (:func:`gdnplan.files.atomic_path`: temp file, fsync, rename), tensors first, and the
card records the SHA-256 of the tensors file it describes (``"tensors_sha256"``). Every read
of a card (:func:`read_card`, :func:`read_weights`) hashes the tensors file beside it and
raises InputError when the hash differs, so a save interrupted between the two renames (new
tensors beside the old card), a card copied next to other tensors, or a tensors file replaced
alone is reported instead of being used; a re-save of identical tensors with a new card is the
only mixed pair that passes, and it is consistent. A card without the field cannot be checked
and is refused, too; the shipped cards in ``weights/`` all carry it. After checking by hand
that a pair belongs together (e.g. weights written before this field existed), record the
hash with ``python -m gdnplan.models.weights seal PATH.safetensors …``.
"""

from __future__ import annotations

import hashlib
import json
import sys
from pathlib import Path

import torch
from safetensors.torch import save_file

from ..assets import is_file
from ..errors import InputError
from ..files import atomic_path, write_text
from .checks import load_tensors, parse_card

TENSORS_HASH = "tensors_sha256"


def card_path(path: Path | str) -> Path:
    """The card beside the weights ``path``: the same name with the suffix ``.json``."""
    return Path(path).with_suffix(".json")


def file_sha256(path: Path | str) -> str:
    """The SHA-256 of the file ``path`` as 64 hex digits."""
    digest = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


def check_pair(path: Path | str, card: dict, what: str = "weights") -> None:
    """InputError unless ``card`` records the SHA-256 of the tensors file ``path``."""
    path, name = Path(path), card_path(path).name
    recorded = card.get(TENSORS_HASH) if isinstance(card, dict) else None
    fix = (
        "save the weights again or restore both files (a training checkpoint: delete both to "
        "start the run over)"
    )
    if not isinstance(recorded, str):
        raise InputError(
            f"{what}: card {name} records no {TENSORS_HASH!r}, so it cannot be checked to "
            f"describe {path.name}; {fix}, or, after checking the pair, run "
            f"`python -m gdnplan.models.weights seal {path}`"
        )
    if not is_file(path, what):
        raise InputError(f"{what}: {path} not found (its card {name} is there)")
    try:
        actual = file_sha256(path)
    except OSError as e:
        raise InputError(f"{what}: cannot read {path} ({e.strerror or e})") from e
    if actual != recorded:
        raise InputError(
            f"{what}: card {name} does not belong to {path.name} (it records tensors "
            f"{recorded[:12]}…, the file is {actual[:12]}…): the pair was written partly, e.g. "
            f"an interrupted save, or one file was replaced; {fix}"
        )


def read_card(path: Path | str, what: str = "weights") -> dict:
    """The JSON card of the weights ``path``, checked against the tensors file (module
    docstring); InputError (prefixed by ``what``) when missing or not the pair's card."""
    if not is_file(path, what):
        raise InputError(
            f"{what}: {path} does not exist or is not a file (give a .safetensors file or a name)"
        )
    card = card_path(path)
    if not is_file(card, what):
        raise InputError(f"{what}: no card {card.name} beside {path}")
    content = parse_card(card, what)
    check_pair(path, content, what)
    return content


def read_weights(path: Path | str, what: str = "weights") -> tuple[dict[str, torch.Tensor], dict]:
    """Tensors and card of the weights ``path``; InputError when either file is missing or
    they are not a pair."""
    path = Path(path)
    if not is_file(path, what):
        raise InputError(f"{what}: {path} not found (or not a file)")
    card = read_card(path, what)
    return load_tensors(path, what), card


def write_json(path: Path | str, obj: dict) -> None:
    """Write ``obj`` as indented JSON to ``path`` atomically (numpy scalars as floats)."""
    write_text(path, json.dumps(obj, indent=2, default=float) + "\n", "weights card")


def write_weights(
    path: Path | str, tensors: dict[str, torch.Tensor], card: dict, what: str = "weights"
) -> Path:
    """Write the weights ``path`` and its card, sealed with the tensors' SHA-256 (directories
    created; ``card`` itself is not modified); returns ``path``."""
    path = Path(path)
    with atomic_path(path, what) as tmp:
        save_file({k: v.contiguous() for k, v in tensors.items()}, str(tmp))
        sealed = {**card, TENSORS_HASH: file_sha256(tmp)}
    write_json(card_path(path), sealed)
    return path


def seal(path: Path | str) -> str:
    """Record the SHA-256 of the tensors ``path`` in its card (for pairs checked by hand)."""
    path, card = Path(path), card_path(path)
    if not path.exists() or not card.exists():
        raise InputError(f"seal: {path} or its card {card.name} not found")
    content = json.loads(card.read_text())
    content[TENSORS_HASH] = file_sha256(path)
    write_json(card, content)
    return content[TENSORS_HASH]


def main(argv: list[str] | None = None) -> None:
    """``python -m gdnplan.models.weights seal PATH…``."""
    args = sys.argv[1:] if argv is None else argv
    if len(args) < 2 or args[0] != "seal":
        sys.exit("usage: python -m gdnplan.models.weights seal PATH.safetensors …")
    for path in args[1:]:
        print(f"{path}: {seal(path)}")


if __name__ == "__main__":
    main()
