"""GraphDistNet weights from a safetensors file and its JSON card (models/weights.py)."""

from __future__ import annotations

import warnings
from pathlib import Path

from ..checks import build_net, card_config, check_depths
from ..threads import check_threads
from ..weights import read_weights
from .config import GraphDistNetConfig
from .model import GraphDistNetModel
from .network import GraphDistNet


def load_graphdistnet_weights(
    path: Path | str, threads: int | None = None, fused: bool | None = None
) -> GraphDistNetModel:
    """A :class:`GraphDistNetModel` from the weights file ``path`` (safetensors) and the JSON
    card beside it, running inference with ``threads`` torch threads (None: the library
    default, 1) and the ``fused`` kernels (None: wherever they serve the network; see
    :class:`GraphDistNetModel`). Old flat cards load unchanged (:mod:`.config`)."""
    threads = check_threads(threads)
    path = Path(path)
    tensors, card = read_weights(path)
    config = card_config(path, card, "GraphDistNet", GraphDistNetConfig.from_dict)
    check_depths(config, tensors, path)
    net = build_net(path, "GraphDistNet", lambda: GraphDistNet(config), tensors)
    model = GraphDistNetModel(net, card, threads=threads, fused=fused)
    model.source = str(path)
    return model


def load_graphdistnet(path: Path | str, threads: int | None = None) -> GraphDistNetModel:
    """Deprecated name of :func:`load_graphdistnet_weights` (a weights file by path)."""
    warnings.warn(
        "gdnplan.models.graphdistnet.load_graphdistnet is deprecated; use "
        "load_graphdistnet_weights (a file) or gdnplan.load_model (a file or a shipped name)",
        DeprecationWarning,
        stacklevel=2,
    )
    return load_graphdistnet_weights(path, threads)
