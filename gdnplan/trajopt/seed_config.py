"""The initial guesses' settings of the planner (:class:`SeedConfig`, the problem file's ``[seed]``
table) and the registry of seed kinds it names (:data:`SEED_KINDS`, filled by
:mod:`gdnplan.trajopt.seeds`). One of the configs of :mod:`gdnplan.trajopt.config`.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from ..errors import InputError
from ..limits import (
    MAX_RRT_TIME,
    MAX_SEEDS,
    MAX_STARTS,
    MAX_TIME_BUDGET,
    check_int,
    check_number,
    plain_fields,
    shown,
)

INITIAL_GUESSES = ("auto", "straight", "rrt")
# seed kind name -> function SeedRequest -> (T, dof) path or None; filled by
# gdnplan.trajopt.seeds (the shipped kinds) and seeds.register_seed_kind
SEED_KINDS: dict[str, Callable] = {}
MISSING_SEED_KINDS: dict[str, str] = {}  # kind name -> why it is not available (its dependency)
# the default: three RRT-Connect seeds (docs/decisions.md#seeds-within-one-call-margin-helper)
DEFAULT_SEEDS = 3


@dataclass(frozen=True)
class SeedConfig:
    """Initial guesses of the Ipopt optimiser (Adam always starts from the straight line).

    Attributes:
        initial: "auto" (the straight line when it is certified free, else seed paths),
            "straight" (the straight line, perturbed by N(0, 0.2 rad) for later seeds) or
            "rrt" (always seed paths).
        count: seed paths refined; the certified path of least path cost Σ‖Δq‖² among them
            is returned. None: ``DEFAULT_SEEDS`` (3) without ``time_budget``; with one, seeds
            until it ends (at most ``limits.MAX_SEEDS``).
        kinds: the seed kinds drawn in turn (seed i is of kind ``kinds[i % len(kinds)]``):
            names of :data:`gdnplan.trajopt.seeds.SEED_KINDS` ("rrt": RRT-Connect;
            "via": RRT-Connect through a random free via point, often another homotopy class;
            "aorrtc": OMPL's AORRTC, with OMPL installed).
        starts: attempts of the first seed: an attempt whose path ends uncertified is
            replaced by a new seed, at most ``starts − 1`` times over the whole call.
        time_budget: wall time (s) of the whole call; when it ends, the best certified path
            found so far is returned (an RRT-Connect run and an Ipopt solve are cut at it).
            None: no budget.
        rrt_time: time limit of one RRT-Connect run (s).
        rrt_step: RRT-Connect extension (rad, joint-space 2-norm); narrow passages (the fetch
            bring-out) may need ~0.3.
        rrt_clearance: extra clearance (m) above the margin demanded of seed paths (at most
            half the start's and goal's own clearance above the margin); when RRT-Connect finds
            no such path, the same seed retries demanding the margin only.
    """

    initial: str = "auto"
    count: int | None = None
    kinds: tuple[str, ...] = ("rrt",)
    starts: int = 3
    time_budget: float | None = None
    rrt_time: float = 5.0
    rrt_step: float = 2.0
    rrt_clearance: float = 0.02

    def __post_init__(self) -> None:
        plain_fields(self)
        if self.initial not in INITIAL_GUESSES:
            raise InputError(
                f"initial: unknown {shown(self.initial)}; choose one of {INITIAL_GUESSES}"
            )
        if self.count is not None:
            check_int(self.count, "count", 1, MAX_SEEDS)
        if isinstance(self.kinds, list):
            object.__setattr__(self, "kinds", tuple(self.kinds))
        if not isinstance(self.kinds, tuple) or not self.kinds:
            raise InputError(f"kinds: expected a list of seed kind names, got {shown(self.kinds)}")
        for kind in self.kinds:
            if isinstance(kind, str) and kind in MISSING_SEED_KINDS:
                raise InputError(f"kinds: seed kind {kind!r} {MISSING_SEED_KINDS[kind]}")
            if not isinstance(kind, str) or kind not in SEED_KINDS:
                raise InputError(
                    f"kinds: unknown seed kind {shown(kind)}; choose from {list(SEED_KINDS)}"
                )
        check_int(self.starts, "starts", 1, MAX_STARTS)
        if self.time_budget is not None:
            budget = check_number(self.time_budget, "time_budget", strict=True)
            if budget > MAX_TIME_BUDGET:
                raise InputError(f"time_budget: {budget} s is over the limit {MAX_TIME_BUDGET} s")
        for name in ("rrt_step",):
            check_number(getattr(self, name), name, strict=True)
        check_number(self.rrt_clearance, "rrt_clearance")
        if check_number(self.rrt_time, "rrt_time", strict=True) > MAX_RRT_TIME:
            raise InputError(f"rrt_time: {self.rrt_time} s is over the limit {MAX_RRT_TIME} s")

    @property
    def seed_count(self) -> int:
        """The number of seeds to refine: ``count``, or its automatic value."""
        if self.count is not None:
            return self.count
        return DEFAULT_SEEDS if self.time_budget is None else MAX_SEEDS
