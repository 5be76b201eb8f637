"""The ablation's steps and budgets (issue #25; :mod:`gdnplan.ablation` trains and scores them).

:data:`STEPS` starts at the paper's network (§IV, :meth:`GraphDistNetConfig.faithful`) and each
step changes one architecture field of the step before (:func:`step_config`). :data:`EPOCHS`
is each environment's budget of Adam steps per step and seed; :data:`BEST` the data and
training seconds of the shipped weights, which :func:`faithful_config` gives the faithful
network for Table I. :class:`Settings` sizes one run.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from .data import DATA_DIR
from .models.graphdistnet import GraphDistNetConfig
from .train import FitConfig, GraphDistNetLoss, TrainConfig

__all__ = [
    "BEST",
    "ENVS",
    "EPOCHS",
    "PATIENCE",
    "STEPS",
    "TABLE2_SETTINGS",
    "Best",
    "Settings",
    "extra_data",
    "faithful_config",
    "step_config",
]

# (name, what changes, the one field changed), cumulative from the paper's network.
STEPS: tuple[tuple[str, str, dict], ...] = (
    ("faithful", "the paper (§IV): random, then argmax partner per graph, two-way", {}),
    ("soft-partners", "soft nearest-node partners instead of argmax", {"cross": "soft_knn"}),
    ("one-way", "cross edges into the robot graph only", {"two_way": False}),
    ("node-distances", "every node's signed distance to the other graph", {"node_distance": True}),
    ("soft-min", "d̂ = soft minimum of node distances + MLP", {"min_readout": True}),
    ("probe-points", "the soft minimum also over 4 points per edge", {"probe_split": 5}),
    ("band", "d̂ = the soft minimum beyond ≈ 2 cm of contact", {"correction_band": 0.01}),
)
ENVS = ("b", "d", "e")
# Epochs per step and seed: about what the 4 × 32 steps trained in 1 200 CPU s on a quiet
# machine (docs/decisions.md, 2026-12-04, fifth session).
EPOCHS = {"a": 50, "b": 50, "c": 50, "d": 10, "e": 10}
PATIENCE = 40  # epochs without a better validation MAE before a step stops early
TABLE2_SETTINGS = ("b", "d")  # environments with a Table II setting of their own


@dataclass(frozen=True)
class Best:
    """Data and training seconds of an environment's shipped weights (weights/<env>.json and
    its lineage: the sum of every training step from scratch)."""

    seconds: float
    n_train: int | None  # first samples of data/<env>/train (None: all 50 000)
    near: bool  # + the 20 000 near-boundary samples of data/near/<env>/train (seed 3)
    compile: bool  # their runs used torch.compile (the cards: d and e)


BEST = {
    "a": Best(2242 + 1560 + 1250, None, True, False),
    "b": Best(447 + 3075, None, False, False),
    "c": Best(1569 + 1608 + 792, None, True, False),
    "d": Best(1218, None, False, False),  # the small soft-minimum network (d_faithful: 4 287 s,
    # the budget of the one-way network shipped before it)
    "e": Best(1207, 45_000, False, False),  # the same small network (e_faithful: 4 573 s)
}


def step_config(step: int) -> GraphDistNetConfig:
    """The network of ``STEPS[step]``: the faithful one with every change up to it."""
    changes: dict = {}
    for _, _, change in STEPS[: step + 1]:
        changes |= change
    return GraphDistNetConfig.faithful().with_(**changes)


def extra_data(env: str, data_root: Path | str) -> tuple[str, ...]:
    return (str(Path(data_root) / "near" / env / "train"),) if BEST[env].near else ()


def faithful_config(
    env: str, data_root: Path | str = DATA_DIR, budget: float | None = None
) -> TrainConfig:
    """The paper's network and loss on the data and time budget of ``env``'s shipped weights
    (:data:`BEST`; ``budget`` overrides the seconds), patience 40, no epoch cap below 1000."""
    best = BEST[env]
    fit = FitConfig(epochs=1000, patience=40, time_budget=budget or best.seconds)
    return TrainConfig(
        GraphDistNetConfig.faithful(),
        GraphDistNetLoss(),
        fit,
        best.n_train,
        extra_data(env, data_root),
        compile=best.compile,
    )


@dataclass(frozen=True)
class Settings:
    """Sizes of one ablation run (:meth:`fast` for CI)."""

    epochs: int | None = None  # epochs per step and seed (None: EPOCHS of the environment)
    batch: int = 256
    sweeps: int = 3  # random start configurations of the joint sweeps
    sweep_steps: int = 200
    timing_batch: int = 256
    table2: int = 20  # reaching problems (0: no Table II column)

    @classmethod
    def fast(cls) -> Settings:
        return cls(epochs=1, batch=16, sweeps=1, sweep_steps=20, timing_batch=16,
                   table2=0)  # fmt: skip

    def epochs_of(self, env: str) -> int:
        """The epochs each step of ``env`` trains for."""
        return self.epochs or EPOCHS[env]
