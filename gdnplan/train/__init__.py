"""Training of the learned distance models (GraphDistNet and ClearanceNet).

Modules by concern:

* :mod:`.fit`: the one training loop :func:`fit` of every model and its schedule
  :class:`FitConfig` (validation split, Adam, learning-rate halving, early stopping, time budget,
  best-state keeping, checkpoints);
* :mod:`.checkpoint`: checkpoints and the resume check;
* :mod:`.loss`: GraphDistNet's loss and its weights :class:`GraphDistNetLoss`;
* :mod:`.tensors`: GraphDistNet's inputs of a dataset and its batched predictions with ∂d̂/∂q;
* :mod:`.report`: Table I metrics of a network on a split, git commit, loss curve, weights file;
* :mod:`.graphdistnet`: :func:`train` (``gdnplan train``) with its :class:`TrainConfig`;
* :mod:`.clearancenet`: ClearanceNet's learner and :func:`train_clearancenet`
  (``gdnplan train --model clearancenet``).

The names below are the public ones (``from gdnplan.train import train, TrainConfig, …``).
"""

from ..metrics import roc_auc
from ..models.graphdistnet import load_graphdistnet_weights as _load_file
from .checkpoint import RESUME_KEYS, check_resume, load_checkpoint, save_checkpoint
from .clearancenet import ClearanceNetLearner, train_and_score
from .clearancenet import train as train_clearancenet
from .fit import PLATEAU, FitConfig, Learner, fit, validation_split
from .graphdistnet import (
    OUT_DIR,
    PRESETS,
    RUNS_DIR,
    GraphDistNetLearner,
    TrainConfig,
    card_settings,
    check_env,
    split_config,
    train,
    validate,
)
from .graphdistnet import (
    _load_init as _load_init,
)
from .loss import GraphDistNetLoss, distance_loss, gradient_loss
from .report import SOURCE_ROOT, evaluate, git_sha, metrics, plot_losses, save_weights
from .tensors import Tensors, forward_with_grad, predict, tensors

load_weights = _load_file  # weights/<env>.safetensors -> GraphDistNetModel
_save_checkpoint, _load_checkpoint = save_checkpoint, load_checkpoint  # older private names

__all__ = [
    "OUT_DIR",
    "PLATEAU",
    "PRESETS",
    "RESUME_KEYS",
    "RUNS_DIR",
    "SOURCE_ROOT",
    "ClearanceNetLearner",
    "FitConfig",
    "GraphDistNetLearner",
    "GraphDistNetLoss",
    "Learner",
    "Tensors",
    "TrainConfig",
    "card_settings",
    "check_env",
    "check_resume",
    "distance_loss",
    "evaluate",
    "fit",
    "forward_with_grad",
    "git_sha",
    "gradient_loss",
    "load_checkpoint",
    "load_weights",
    "metrics",
    "plot_losses",
    "predict",
    "roc_auc",
    "save_checkpoint",
    "save_weights",
    "split_config",
    "tensors",
    "train",
    "train_and_score",
    "train_clearancenet",
    "validate",
    "validation_split",
]
