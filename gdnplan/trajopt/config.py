"""Planner settings, one small frozen dataclass per concern, each checked when made.

=================== ====================== ==================================================
config              problem-file table     concern
=================== ====================== ==================================================
:class:`SeedConfig`   ``[seed]``           initial guesses: the straight line, RRT-Connect
                                           seeds, how many seeds, the wall-time budget
:class:`RefineConfig` ``[refine]``         the continuous certificate and the refine rounds
:class:`IpoptConfig`  ``[ipopt]``          Ipopt's NLP: check points, distance rows, stops
:class:`AdamConfig`   ``[adam]``           the paper's Adam baseline
:class:`PlanConfig`   (all four)           one of each; the optimiser is the type of
                                           ``PlanConfig.optimizer`` (IpoptConfig or AdamConfig)
=================== ====================== ==================================================

:class:`SeedConfig` and the seed kinds' registry are :mod:`gdnplan.trajopt.seed_config`'s
(re-exported here). A wrong type, NaN/inf or a value past its limit (:mod:`gdnplan.limits`) is
an InputError naming the setting. :func:`gdnplan.plan` takes any of ``PlanConfig``,
``IpoptConfig`` or ``AdamConfig`` as ``solver``; an optimiser config alone keeps the problem's
seed and refine settings and picks that optimiser.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields, replace

from ..errors import InputError
from ..flags import check_flag
from ..limits import (
    MAX_ADAM_ITERATIONS,
    MAX_INTERPOLATED,
    MAX_ITER,
    MAX_REFINE_ROUNDS,
    MAX_WAYPOINTS,
    check_int,
    check_ipopt,
    check_number,
    plain_fields,
)
from .seed_config import DEFAULT_SEEDS as DEFAULT_SEEDS
from .seed_config import INITIAL_GUESSES as INITIAL_GUESSES
from .seed_config import MISSING_SEED_KINDS as MISSING_SEED_KINDS
from .seed_config import SEED_KINDS as SEED_KINDS
from .seed_config import SeedConfig as SeedConfig


def _check_bools(cfg, names: tuple[str, ...]) -> None:
    """Each flag ``names`` of the frozen ``cfg`` checked (:func:`gdnplan.flags.check_flag`) and
    stored as a Python bool (a numpy bool would not serialise to JSON)."""
    for name in names:
        object.__setattr__(cfg, name, check_flag(getattr(cfg, name), name, lowercase=True))


@dataclass(frozen=True)
class RefineConfig:
    """The continuous certificate and the refine rounds after each solve.

    Attributes:
        ccd: refine the check points of segments the continuous certificate rejects and
            re-solve.
        rounds: re-solves with refined check points (with ``ccd``).
        warm_start: (Ipopt) start each refine round from the last round's solution and
            multipliers (new check points start with zero multipliers).
        clearance_buffer: (Ipopt) the check points demand d ≥ max(margin, c + clearance_buffer)
            (m), c the problem's certified clearance: Ipopt leaves active check points a hair
            inside their bound, which a certificate at exactly that bound rejects, and the
            buffer leaves the path room to bend between check points.
        raise_window: (Ipopt, learned models) a refine round raises the model's margin on the
            rejected segments and this many segments either side of each; None: on the
            whole path (docs/decisions.md#raise-window). With ``exact_rows``: the segments
            that get coal rows.
        exact_rows: (Ipopt, learned models) a refine round constrains the check points of
            those segments by coal's exact distance instead of the model's raised bound
            (:mod:`gdnplan.trajopt.refine`); a polish or repair solve starts with coal rows
            where the solve that made its path had them.
        polish: (Ipopt) more solves from the cheapest certified path with tighter stops,
            more check points and smaller buffers; each kept when certified and cheaper
            (:func:`gdnplan.trajopt.polish.polish`).
        repair: (Ipopt) when no seed's path was certified, one more solve from the last path
            with more check points and a wider buffer (:func:`gdnplan.trajopt.polish.repair`).
    """

    ccd: bool = True
    rounds: int = 3
    warm_start: bool = True
    clearance_buffer: float = 0.002
    raise_window: int | None = 2
    exact_rows: bool = True
    polish: bool = True
    repair: bool = True

    def __post_init__(self) -> None:
        plain_fields(self)
        _check_bools(self, ("ccd", "warm_start", "exact_rows", "polish", "repair"))
        check_int(self.rounds, "rounds", 0, MAX_REFINE_ROUNDS)
        check_number(self.clearance_buffer, "clearance_buffer")
        if self.raise_window is not None:
            check_int(self.raise_window, "raise_window", 0, MAX_WAYPOINTS)


@dataclass(frozen=True)
class IpoptConfig:
    """The Ipopt optimiser (direct transcription, :mod:`gdnplan.trajopt`).

    Attributes:
        interpolated: M check points strictly between consecutive waypoints (before
            refining); each replaced attempt adds one (see ``SeedConfig.starts``; the
            planner's own additions stop at ``limits.MAX_INTERPOLATED``); the
            certificate and refine rounds catch what sparse check points miss
            (docs/decisions.md#ipopt-check-points-per-segment).
        per_link: one distance row per link polygon (capped at ``link_cap``) instead of one;
            None: when the model provides per-link distances (coal does).
        link_cap: per-link distances above this (m) are reported as the cap (inactive rows).
        max_iter: Ipopt iteration cap per solve.
        tol: Ipopt tolerance.
        obj_change_tol: Ipopt also stops ("acceptable") once the relative change of the path
            cost stays below this for 3 iterations at a feasible point (constraint violation
            ≤ 1e-5): the certificate, not the KKT residual, judges the result
            (docs/decisions.md#ipopt-stop-on-path-cost-stagnation).
        options: extra Ipopt options (name → value, :data:`gdnplan.limits.IPOPT_OPTIONS`)
            over gdnplan's, e.g. ``{"limited_memory_initialization": "scalar1"}``.
    """

    interpolated: int = 2
    per_link: bool | None = None
    link_cap: float = 0.3
    max_iter: int = 150
    tol: float = 1e-3
    obj_change_tol: float = 1e-3
    options: dict = field(default_factory=dict)

    def __post_init__(self) -> None:
        plain_fields(self)
        check_int(self.interpolated, "interpolated", 0, MAX_INTERPOLATED)
        if self.per_link is not None:
            _check_bools(self, ("per_link",))
        check_int(self.max_iter, "max_iter", 1, MAX_ITER)
        for name in ("link_cap", "tol", "obj_change_tol"):
            check_number(getattr(self, name), name, strict=True)
        check_ipopt(self.options)


@dataclass(frozen=True)
class AdamConfig:
    """The paper's baseline: Adam on the collision cost C(d) = c / ((d − margin)² + ε) plus
    the path cost, from the straight line (:func:`gdnplan.trajopt.adam.collision_cost`).

    Attributes:
        interpolated: M check points strictly between consecutive waypoints (Adam's stop
            test reads the check points alone, so it keeps the paper-baseline density).
        iterations: iteration cap.
        lr: step size (rad).
        c: the collision cost's constant c.
        eps: the collision cost's ε.
        stop: stop once every check point is this far above the margin (m).
    """

    interpolated: int = 3
    iterations: int = 500
    lr: float = 0.05
    c: float = 1e-3
    eps: float = 1e-3
    stop: float = 0.01

    def __post_init__(self) -> None:
        plain_fields(self)
        check_int(self.interpolated, "interpolated", 0, MAX_INTERPOLATED)
        check_int(self.iterations, "iterations", 1, MAX_ADAM_ITERATIONS)
        for name in ("lr", "c", "eps"):
            check_number(getattr(self, name), name, strict=True)
        check_number(self.stop, "stop")


Optimizer = IpoptConfig | AdamConfig


@dataclass(frozen=True)
class PlanConfig:
    """Every planner setting: one config per concern; ``optimizer``'s type picks the optimiser."""

    seed: SeedConfig = field(default_factory=SeedConfig)
    refine: RefineConfig = field(default_factory=RefineConfig)
    optimizer: IpoptConfig | AdamConfig = field(default_factory=IpoptConfig)

    def __post_init__(self) -> None:
        for name, kind in (("seed", SeedConfig), ("refine", RefineConfig)):
            if not isinstance(getattr(self, name), kind):
                raise InputError(
                    f"{name}: expected {kind.__name__}, got {type(getattr(self, name)).__name__}"
                )
        if not isinstance(self.optimizer, (IpoptConfig, AdamConfig)):
            raise InputError(
                f"optimizer: expected IpoptConfig or AdamConfig, got "
                f"{type(self.optimizer).__name__}"
            )

    def checked(self) -> PlanConfig:
        """A copy with every config's checks re-run (a frozen dataclass can still be forged)."""
        return PlanConfig(replace(self.seed), replace(self.refine), replace(self.optimizer))

    @property
    def interpolated(self) -> int:
        """The optimiser's check points per segment before refining."""
        return self.optimizer.interpolated


def more_check_points(optimizer: IpoptConfig, extra: int) -> IpoptConfig:
    """``optimizer`` with ``extra`` ≥ 0 more check points per segment, at most
    ``MAX_INTERPOLATED``: the check points the planner adds itself (a replaced attempt, the
    polish and the repair solves) stop at the limit of the caller's setting (making the config
    anew with ``interpolated`` past it raised an InputError naming a setting never given)."""
    return replace(optimizer, interpolated=min(optimizer.interpolated + extra, MAX_INTERPOLATED))


OPTIMIZERS: dict[str, type] = {"ipopt": IpoptConfig, "adam": AdamConfig}


def with_optimizer(config: PlanConfig, name: str) -> PlanConfig:
    """``config`` with the optimiser ``name`` ("ipopt" or "adam"): its own optimiser settings
    when they are of that kind, else that optimiser's defaults."""
    if name not in OPTIMIZERS:
        raise InputError(f"solver: unknown {name!r}; choose 'ipopt' or 'adam'")
    own = isinstance(config.optimizer, OPTIMIZERS[name])
    return replace(config, optimizer=config.optimizer if own else OPTIMIZERS[name]())


CONFIG_TABLES: dict[str, type] = {  # problem-file table -> its config
    "seed": SeedConfig,
    "refine": RefineConfig,
    "ipopt": IpoptConfig,
    "adam": AdamConfig,
}


def config_keys(kind: type) -> frozenset[str]:
    """The field names of a config dataclass (a problem-file table's keys)."""
    return frozenset(f.name for f in fields(kind))


def finite_budget(budget: float | None) -> float:
    """``time_budget`` as seconds, +inf for None."""
    return math.inf if budget is None else float(budget)


__all__ = [
    "CONFIG_TABLES",
    "INITIAL_GUESSES",
    "AdamConfig",
    "IpoptConfig",
    "Optimizer",
    "PlanConfig",
    "RefineConfig",
    "SeedConfig",
    "config_keys",
    "more_check_points",
    "with_optimizer",
]
