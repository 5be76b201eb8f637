"""GraphDistNet-3D weights files: ``<path>.safetensors`` (the state dict) and ``<path>.json``
(the card, with ``"model": "graphdistnet3d"``, the architecture as ``config`` and its measured
metrics), as :func:`gdnplan.train.graphdistnet3d.export_weights` writes them."""

from __future__ import annotations

from pathlib import Path

from ...errors import InputError
from ..weights import read_weights
from .config import GraphDistNet3DConfig
from .model import GraphDistNet3DModel
from .network import GraphDistNet3D


def load_graphdistnet3d(
    path: Path | str, threads: int | None = None, fused: bool | None = None
) -> GraphDistNet3DModel:
    """The DistanceModel of a weights file (InputError for a card of another model); ``fused``
    as in :class:`GraphDistNet3DModel`."""
    tensors, card = read_weights(path)
    if card.get("model") != "graphdistnet3d":
        raise InputError(f"weights: {path} holds a {card.get('model')!r} model, not graphdistnet3d")
    net = GraphDistNet3D(GraphDistNet3DConfig.from_dict(card["config"]))
    net.load_state_dict(tensors)
    return GraphDistNet3DModel(net, card, threads=threads, fused=fused)
