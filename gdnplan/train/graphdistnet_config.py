"""The settings of one GraphDistNet training run (:func:`gdnplan.train.graphdistnet.train`):
:class:`TrainConfig` (architecture, loss, schedule, data), the architecture presets, the flat
settings recorded in a weights card, and the deprecated keyword form of ``train``.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field, fields
from pathlib import Path

from ..errors import InputError
from ..flags import check_flag
from ..models.graphdistnet import GraphDistNetConfig
from ..models.weights import read_card
from .fit import FitConfig
from .loss import GraphDistNetLoss

PRESETS = {"faithful": GraphDistNetConfig.faithful, "smooth": GraphDistNetConfig.smooth}


@dataclass(frozen=True)
class TrainConfig:
    """One GraphDistNet training run, one field per concern.

    Attributes:
        network: the architecture (``scale`` and ``origin`` are set from the robot).
        loss: the loss weights.
        fit: the schedule (batch, lr, epochs, patience, time budget, seed, device).
        n_train: use only the first n samples of ``data/<env>/train`` (incl. the 10 %
            validation part), or None for all.
        extra: more training splits (directories of shards, e.g. near-boundary samples from
            ``gdnplan generate --near``), added to the training part only: validation stays
            the 10 % of ``data/<env>/train``, the distribution of the test split.
        init: fine-tune: start from these weights (same architecture as ``network``) instead
            of a random initialisation; ignored when the run resumes from its checkpoint.
        compile: ``torch.compile`` the training step; validation and evaluation stay eager.
    """

    network: GraphDistNetConfig = field(default_factory=GraphDistNetConfig.smooth)
    loss: GraphDistNetLoss = field(default_factory=GraphDistNetLoss)
    fit: FitConfig = field(default_factory=FitConfig)
    n_train: int | None = None
    extra: tuple[Path | str, ...] = ()
    init: Path | str | None = None
    compile: bool = False

    def __post_init__(self) -> None:
        n = self.n_train
        if n is not None and (isinstance(n, bool) or not isinstance(n, int) or n < 2):
            raise InputError(f"n_train: expected an integer ≥ 2, got {n!r}")
        object.__setattr__(self, "compile", check_flag(self.compile, "compile"))
        if self.compile and self.loss.grad_weight > 0:
            raise InputError(
                "compile: the gradient loss (grad_weight > 0) differentiates ∂d̂/∂q, a double "
                "backward that torch.compile does not support; train it without --compile"
            )
        object.__setattr__(self, "extra", tuple(self.extra))


def split_config(flat: dict) -> tuple[GraphDistNetConfig, GraphDistNetLoss]:
    """The architecture and the loss of one flat dict (an old card's ``config``, or a new
    card's ``config`` with its ``training.loss``, plus ``--set`` overrides)."""
    return GraphDistNetConfig.from_dict(flat), GraphDistNetLoss.from_dict(flat)


def card_settings(weights: Path | str, what: str = "--init") -> dict:
    """The flat settings (architecture and loss) recorded in the card of ``weights``."""
    card = read_card(weights, what)
    config = card.get("config")
    if not isinstance(config, dict):
        raise InputError(f"{what}: the card of {weights} has no 'config' object")
    training = card.get("training")
    loss = training.get("loss") if isinstance(training, dict) else None
    return {**config, **(loss if isinstance(loss, dict) else {})}


LEGACY = ("n_train", "batch", "lr", "epochs", "patience", "time_budget", "seed", "device",
          "compile", "init", "extra", "loss")  # fmt: skip


def legacy_config(config: GraphDistNetConfig | None, legacy: dict) -> TrainConfig:
    """The TrainConfig of an old-style call ``train(env, GraphDistNetConfig, batch=…, …)``."""
    unknown = sorted(set(legacy) - set(LEGACY))
    if unknown:
        raise TypeError(f"train() got unexpected keyword arguments {unknown}")
    warnings.warn(
        "train(env, GraphDistNetConfig, batch=…, lr=…, …) is deprecated; pass "
        "gdnplan.train.TrainConfig(network=…, loss=…, fit=FitConfig(…), …)",
        DeprecationWarning,
        stacklevel=3,
    )
    names = {f.name for f in fields(FitConfig)}
    schedule = FitConfig(**{k: v for k, v in legacy.items() if k in names})
    rest = {k: v for k, v in legacy.items() if k not in names}
    return TrainConfig(network=config or GraphDistNetConfig.smooth(), fit=schedule, **rest)
