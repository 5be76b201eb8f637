"""GraphDistNet-3D weights files: ``<path>.safetensors`` (the state dict) and ``<path>.json``
(the card, with ``"model": "graphdistnet3d"``, the architecture as ``config`` and its measured
metrics), as :func:`gdnplan.train.graphdistnet3d.export_weights` writes them; and a network
started from a weights file (:func:`init_from_weights`, a training run's ``--init``)."""

from __future__ import annotations

from pathlib import Path

import torch

from ...errors import InputError
from ..checks import build_net, card_config, check_depths
from ..threads import check_threads
from ..weights import read_weights
from .config import GraphDistNet3DConfig
from .model import GraphDistNet3DModel
from .network import GraphDistNet3D


def read_graphdistnet3d(path: Path | str) -> tuple[dict[str, torch.Tensor], dict]:
    """Tensors and card of a GraphDistNet-3D weights file (InputError for another model)."""
    tensors, card = read_weights(path)
    if card.get("model") != "graphdistnet3d":
        raise InputError(f"weights: {path} holds a {card.get('model')!r} model, not graphdistnet3d")
    return tensors, card


def load_graphdistnet3d(
    path: Path | str, threads: int | None = None, fused: bool | None = None
) -> GraphDistNet3DModel:
    """The DistanceModel of a weights file (InputError for a card of another model, a config
    field of the wrong type or range, or tensors that do not fit the config's network, all
    before anything runs); ``fused`` as in :class:`GraphDistNet3DModel`."""
    threads = check_threads(threads)
    path = Path(path)
    tensors, card = read_graphdistnet3d(path)
    config = card_config(path, card, "GraphDistNet-3D", GraphDistNet3DConfig.from_dict)
    check_depths(config, tensors, path)
    net = build_net(path, "GraphDistNet-3D", lambda: GraphDistNet3D(config), tensors)
    model = GraphDistNet3DModel(net, card, threads=threads, fused=fused)
    model.source = str(path)
    return model


def init_from_weights(net: GraphDistNet3D, path: Path | str) -> list[str]:
    """Copy the tensors of the weights ``path`` into ``net`` and return the names of ``net``'s
    parameters the file does not hold (they keep their initialisation: e.g. the node estimates
    of ``min_readout`` when the file is a plain network's). InputError when the file holds a
    tensor ``net`` lacks or of another shape, or an architecture whose normalisation (scale,
    length, origin) differs from ``net``'s: the copied function would not be the file's."""
    tensors, card = read_graphdistnet3d(path)
    theirs = card_config(Path(path), card, "GraphDistNet-3D", GraphDistNet3DConfig.from_dict)
    ours = net.config
    for key in ("scale", "length", "origin", "rim"):
        if getattr(theirs, key) != getattr(ours, key):
            raise InputError(
                f"init: {path} has {key} = {getattr(theirs, key)!r}, the network "
                f"{getattr(ours, key)!r}; start from the card's config"
            )
    own = net.state_dict()
    for name, t in tensors.items():
        if name not in own or own[name].shape != t.shape:
            shape = None if name not in own else tuple(own[name].shape)
            raise InputError(
                f"init: {path} tensor {name} {tuple(t.shape)} does not fit the network "
                f"({shape}); start from the card's config"
            )
    net.load_state_dict({**own, **tensors})
    return [name for name in own if name not in tensors]
