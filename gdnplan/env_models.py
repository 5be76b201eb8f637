"""The learned models of a paper environment by its name, from a folder of weights (Table I,
Fig. 5, ``gdnplan evaluate``): :func:`graphdistnet_of_env` and :func:`clearancenet_of_env`
return None when the environment's file is missing. A weights file by path, or a shipped name:
:func:`gdnplan.load_model`."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np

from .assets import WEIGHTS_DIR
from .data import Dataset
from .errors import InputError
from .limits import MAX_DRAWS, check_int
from .models import DistanceModel


class BatchedGraphDistNet:
    """GraphDistNet with :meth:`predict_dataset`: one batched pass over samples with their own
    obstacle graphs (graph construction included), via :mod:`gdnplan.train`'s tensors.

    ``draws`` R > 1 (the paper's network only, ``cross="argmax"``, whose first layer picks a
    random partner per graph): :meth:`predict_dataset` returns the mean over R draws of that
    pick (generator seeds 0 … R − 1), d̄ = (1/R) Σ_r d̂_r and ∂d̄/∂q = (1/R) Σ_r ∂d̂_r/∂q, an
    estimate of d̂'s expectation over the draw; R = 1 is the one draw of seed 0. The per-scene
    :meth:`distance` and :meth:`distance_and_grad` stay one draw.
    """

    name = "GraphDistNet"
    is_distance = True

    def __init__(self, model, draws: int = 1):
        from .models.graphdistnet import GraphDistNetModel

        if not isinstance(model, GraphDistNetModel):
            raise InputError(
                f"model: expected a planar GraphDistNet (gdnplan.models.graphdistnet), got "
                f"{type(model).__name__}"
            )
        draws = check_int(draws, "draws", 1, MAX_DRAWS)
        if draws > 1 and model.config.cross != "argmax":
            raise InputError(
                "draws: only the paper's network (cross='argmax') draws a random partner; "
                f"this one has cross={model.config.cross!r}"
            )
        self.model = model
        self.draws = draws

    def distance(self, scene, q: np.ndarray) -> np.ndarray:
        return self.model.distance(scene, q)

    def distance_and_grad(self, scene, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        return self.model.distance_and_grad(scene, q)

    def predict_dataset(self, ds: Dataset, grad: bool) -> tuple[np.ndarray, np.ndarray | None]:
        from .train import predict as predict_net
        from .train import tensors

        t = tensors(ds)
        runs = [predict_net(self.model.net, t, grad=grad, seed=r) for r in range(self.draws)]
        d = np.mean([r[0] for r in runs], axis=0)
        return d, (np.mean([r[1] for r in runs], axis=0) if grad else None)


def graphdistnet_of_env(env: str, weights_dir: Path = WEIGHTS_DIR) -> DistanceModel | None:
    """Environment ``env``'s GraphDistNet for Table I, from ``<weights_dir>/<env>.safetensors``
    (batched over datasets), or None when that file is missing."""
    path = Path(weights_dir) / f"{env}.safetensors"
    if not path.exists():
        return None
    from .models import load_model

    return BatchedGraphDistNet(load_model(path))


def clearancenet_of_env(env: str, weights_dir: Path = WEIGHTS_DIR) -> DistanceModel | None:
    """Environment ``env``'s ClearanceNet for Table I, from
    ``<weights_dir>/clearancenet_<env>.safetensors``, or None when that file is missing."""
    from .models.clearancenet import load as load_cn

    path = Path(weights_dir) / f"clearancenet_{env}.safetensors"
    return load_cn(path) if path.exists() else None


def _deprecated(old: str, new):
    def alias(*args, **kwargs):
        warnings.warn(
            f"gdnplan.evaluate.{old} is deprecated; use gdnplan.evaluate.{new.__name__} (by "
            "environment name) or gdnplan.load_model (a weights file or shipped name)",
            DeprecationWarning,
            stacklevel=2,
        )
        return new(*args, **kwargs)

    alias.__name__ = old
    alias.__doc__ = f"Deprecated name of :func:`{new.__name__}`."
    return alias


load_graphdistnet = _deprecated("load_graphdistnet", graphdistnet_of_env)
load_clearancenet = _deprecated("load_clearancenet", clearancenet_of_env)
