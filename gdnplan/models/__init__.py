"""Collision-distance models behind one interface: coal ground truth and learned estimators.

Every model maps a scene and a batch of configurations q (B, dof) to distances d (B,) in metres
(positive = free) and, with ``distance_and_grad``, to ∂d/∂q (B, dof), float64 at the API.
Planners, the CasADi bridge and the evaluation take any :class:`DistanceModel`.
"""

from __future__ import annotations

from pathlib import Path
from typing import Protocol, runtime_checkable

import numpy as np

from ..assets import weights_file
from ..distance import signed_distance, signed_distance_and_grad
from ..errors import UnknownNameError
from ..limits import shown
from ..scene import Scene
from .threads import inference_threads, set_inference_threads


@runtime_checkable
class DistanceModel(Protocol):
    """What every collision-distance model provides.

    Optional: ``distance_deferred_grad(scene, q) -> (d (B,), grad)``, where ``grad()`` returns
    ∂d/∂q (B, dof) when called (GraphDistNet). The CasADi bridge then skips the gradient of
    points whose Jacobian the solver never asks for.
    """

    name: str

    def distance(self, scene: Scene, q: np.ndarray) -> np.ndarray:
        """(B,) distances (m) of configurations q (B, dof) or (dof,)."""
        ...

    def distance_and_grad(self, scene: Scene, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """((B,), (B, dof)) distances and their gradients with respect to q."""
        ...


class CoalModel:
    """Exact signed distance from coal (the ground truth) as a :class:`DistanceModel`."""

    name = "coal"

    def distance(self, scene: Scene, q: np.ndarray) -> np.ndarray:
        return signed_distance(scene, q)

    def distance_and_grad(self, scene: Scene, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        return signed_distance_and_grad(scene, q)


def load_model(weights: Path | str, threads: int | None = None) -> DistanceModel:
    """Load a trained model: shipped weights by name or a ``.safetensors`` file with its card.

    ``weights``: a shipped name (``"d"``, ``"ur5e"``, ``"clearancenet_b"``; see
    :func:`gdnplan.assets.weights_names`) or a path to a ``.safetensors`` file whose JSON card
    sits beside it. The card's ``"model"`` field selects the class (``"graphdistnet"``,
    ``"clearancenet"``, ``"graphdistnet3d"``). The model refuses scenes of a robot it was not
    trained for.
    ``threads``: torch threads of its inference (None: the library default, 1;
    :mod:`gdnplan.models.threads`); the model's ``threads`` attribute can be changed later.
    """
    from .weights import card_path, read_card  # imports torch: only for learned models

    path = weights_file(weights)
    kind = read_card(path).get("model")
    if kind == "graphdistnet":
        from .graphdistnet import load_graphdistnet_weights

        return load_graphdistnet_weights(path, threads)
    if kind == "clearancenet":
        from .clearancenet import load as load_clearancenet

        return load_clearancenet(path, threads)
    if kind == "graphdistnet3d":
        from .graphdistnet3d import load_graphdistnet3d

        return load_graphdistnet3d(path, threads)
    raise UnknownNameError(
        f'model: unknown model type {shown(kind)} in {card_path(path).name}; its "model" '
        "field names one of 'graphdistnet', 'clearancenet', 'graphdistnet3d' (a card of "
        "another tool, or a damaged one: re-download or retrain the weights)"
    )


__all__ = ["CoalModel", "DistanceModel", "inference_threads", "load_model", "set_inference_threads"]
