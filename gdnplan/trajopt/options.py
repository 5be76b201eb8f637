"""The deprecated option bag :class:`TrajoptOptions` (use the configs of
:mod:`gdnplan.trajopt.config`) and where each of its fields lives now (:data:`OLD_KEYS`, also
the map of a problem file's old ``[solver]`` table)."""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field, fields

from ..errors import InputError
from ..flags import check_flag
from ..limits import (
    MAX_ADAM_ITERATIONS,
    MAX_INTERPOLATED,
    MAX_ITER,
    MAX_REFINE_ROUNDS,
    MAX_RRT_TIME,
    MAX_STARTS,
    MAX_WAYPOINTS,
    check_int,
    check_ipopt,
    check_number,
    plain_fields,
)
from .config import (
    INITIAL_GUESSES,
    AdamConfig,
    IpoptConfig,
    PlanConfig,
    RefineConfig,
    SeedConfig,
)

IPOPT_INTERPOLATED, ADAM_INTERPOLATED = IpoptConfig.interpolated, AdamConfig.interpolated
REMOVED = "removed (no shipped default, problem, benchmark or weights used it)"
# old field -> (problem-file table, key there) of its new home; None: removed
OLD_KEYS: dict[str, tuple[str, str] | None] = {
    "initial": ("seed", "initial"),
    "starts": ("seed", "starts"),
    "rrt_clearance": ("seed", "rrt_clearance"),
    "rrt_time": ("seed", "rrt_time"),
    "rrt_step": ("seed", "rrt_step"),
    "ccd": ("refine", "ccd"),
    "refine_rounds": ("refine", "rounds"),
    "warm_start": ("refine", "warm_start"),
    "clearance_buffer": ("refine", "clearance_buffer"),
    "raise_window": ("refine", "raise_window"),
    "interpolated": ("ipopt", "interpolated"),  # or [adam]'s, for the Adam optimiser
    "per_link": ("ipopt", "per_link"),
    "link_cap": ("ipopt", "link_cap"),
    "max_iter": ("ipopt", "max_iter"),
    "tol": ("ipopt", "tol"),
    "obj_change_tol": ("ipopt", "obj_change_tol"),
    "ipopt": ("ipopt", "options"),
    "adam_iterations": ("adam", "iterations"),
    "adam_lr": ("adam", "lr"),
    "adam_c": ("adam", "c"),
    "adam_eps": ("adam", "eps"),
    "adam_stop": ("adam", "stop"),
    "learned_margin": None,
}


@dataclass(frozen=True)
class TrajoptOptions:
    """Deprecated: use :class:`~gdnplan.trajopt.config.SeedConfig`, ``RefineConfig``,
    ``IpoptConfig`` and ``AdamConfig`` (in a :class:`~gdnplan.trajopt.config.PlanConfig`);
    :meth:`to_config` converts, :data:`OLD_KEYS` says where each field went. Making one warns
    (DeprecationWarning). ``learned_margin`` is removed: only 0 is accepted by :meth:`to_config`.

    Solver settings, checked when made:
    a wrong type, NaN/inf or a value past its limit (:mod:`gdnplan.limits`: refine_rounds ≤ 8,
    interpolated ≤ 50, 1 ≤ starts ≤ 50, 1 ≤ max_iter ≤ 10 000, 1 ≤ adam_iterations ≤ 100 000,
    0 < rrt_time ≤ 600 s, ipopt options from an allow-list) is an InputError.

    Attributes:
        initial: "auto" (straight line when certified free, else RRT-Connect seeds),
            "straight" (always the straight line) or "rrt" (always RRT-Connect seeds).
        ccd: refine the check points of segments the continuous certificate rejects.
        refine_rounds: re-solves with refined check points (with ``ccd``).
        warm_start: start each refine round from the last round's solution and multipliers
            (Ipopt's warm start; new check points start with zero multipliers).
        per_link: one distance row per link polygon (capped at ``link_cap``) instead of one;
            None: when the model provides per-link distances (coal does).
        interpolated: M check points strictly between consecutive waypoints (before refining);
            None: 2 for Ipopt, 3 for Adam; Ipopt adds one per restart (``_plan_ipopt``).
            2 for Ipopt: a network pass costs about linearly in the check points and the CCD
            certificate and refine rounds catch what the sparser check points miss
            (docs/decisions.md#ipopt-check-points-per-segment). Adam's stop test reads the
            check points alone, so Adam keeps the paper-baseline density.
        starts: Ipopt attempts (new seed path each) before giving up.
        max_iter: Ipopt iteration cap per attempt.
        tol: Ipopt tolerance.
        obj_change_tol: Ipopt also stops ("acceptable") once the relative change of the path
            cost stays below this for 3 iterations at a feasible point (constraint violation
            ≤ 1e-5): the certified check, not the KKT residual, judges the result
            (docs/decisions.md#ipopt-stop-on-path-cost-stagnation).
        clearance_buffer: the check points demand d ≥ max(margin, c + clearance_buffer) (m),
            c the problem's certified clearance (``Problem.certified_clearance``, the margin by
            default): Ipopt leaves active check points a hair inside their bound (d ≈ bound −
            1e-8), which a certificate at exactly that bound rejects as a configuration within
            it, and the buffer also leaves the path room to bend between check points.
        learned_margin: removed; must be 0.
        raise_window: a refine round raises a learned model's margin on the rejected
            segments and this many segments either side of each; None: on the whole path
            (docs/decisions.md#raise-window).
        rrt_clearance: extra clearance (m) above the margin demanded of seed paths (at most
            half the start's and goal's own clearance above the margin); when RRT-Connect finds
            no such path, the same attempt retries demanding the margin only (narrow passages).
        rrt_time: time limit of one RRT-Connect run (s).
        rrt_step: RRT-Connect extension (rad, joint-space 2-norm); long steps were fastest on
            environment (d), narrow passages (fetch) may need ~0.3.
        link_cap: per-link distances above this (m) are reported as the cap (inactive rows).
        ipopt: extra Ipopt options (name → value) over the defaults, e.g.
            ``{"limited_memory_initialization": "scalar1"}`` (Ipopt's own default).
        adam_iterations: the paper's Adam optimiser: iteration cap.
        adam_lr: the Adam optimiser's step size (rad).
        adam_c: the Adam optimiser's collision-cost constant c.
        adam_eps: the Adam optimiser's collision-cost ε.
        adam_stop: the Adam optimiser stops once every check point is this far above the
            margin (m).
    """

    initial: str = "auto"
    ccd: bool = True
    refine_rounds: int = 3
    warm_start: bool = True
    per_link: bool | None = None
    interpolated: int | None = None
    starts: int = 3
    max_iter: int = 150
    tol: float = 1e-3
    obj_change_tol: float = 1e-3
    rrt_clearance: float = 0.02
    clearance_buffer: float = 0.002
    learned_margin: float = 0.0
    raise_window: int | None = 2
    rrt_time: float = 5.0
    rrt_step: float = 2.0
    link_cap: float = 0.3
    ipopt: dict = field(default_factory=dict)
    adam_iterations: int = 500
    adam_lr: float = 0.05
    adam_c: float = 1e-3
    adam_eps: float = 1e-3
    adam_stop: float = 0.01

    def __post_init__(self) -> None:
        """InputError naming the setting for a wrong type, NaN/inf or a value past its limit
        (limits in :mod:`gdnplan.limits`)."""
        plain_fields(self)
        if self.initial not in INITIAL_GUESSES:
            raise InputError(f"initial: unknown {self.initial!r}; choose one of {INITIAL_GUESSES}")
        for name in ("ccd", "warm_start") + (("per_link",) if self.per_link is not None else ()):
            object.__setattr__(self, name, check_flag(getattr(self, name), name, lowercase=True))
        check_int(self.refine_rounds, "refine_rounds", 0, MAX_REFINE_ROUNDS)
        if self.interpolated is not None:
            check_int(self.interpolated, "interpolated", 0, MAX_INTERPOLATED)
        if self.raise_window is not None:
            check_int(self.raise_window, "raise_window", 0, MAX_WAYPOINTS)
        check_int(self.starts, "starts", 1, MAX_STARTS)
        check_int(self.max_iter, "max_iter", 1, MAX_ITER)
        check_int(self.adam_iterations, "adam_iterations", 1, MAX_ADAM_ITERATIONS)
        for name in ("tol", "obj_change_tol", "rrt_step", "link_cap", "adam_lr", "adam_c"):
            check_number(getattr(self, name), name, strict=True)
        check_number(self.adam_eps, "adam_eps", strict=True)
        for name in ("rrt_clearance", "clearance_buffer", "learned_margin", "adam_stop"):
            check_number(getattr(self, name), name)
        if check_number(self.rrt_time, "rrt_time", strict=True) > MAX_RRT_TIME:
            raise InputError(f"rrt_time: {self.rrt_time} s is over the limit {MAX_RRT_TIME} s")
        check_ipopt(self.ipopt)
        warnings.warn(
            "TrajoptOptions is deprecated; use gdnplan.PlanConfig(seed=SeedConfig(...), "
            "refine=RefineConfig(...), optimizer=IpoptConfig(...) or AdamConfig(...))",
            DeprecationWarning,
            stacklevel=3,
        )

    def to_config(self, solver: str = "ipopt") -> PlanConfig:
        """The same settings as a PlanConfig whose optimiser is ``solver`` ("ipopt"/"adam")."""
        if self.learned_margin != 0:
            raise InputError(f"learned_margin: {REMOVED}; leave it out")
        tables: dict[str, dict] = {"seed": {}, "refine": {}, "ipopt": {}, "adam": {}}
        for name, home in OLD_KEYS.items():
            value = getattr(self, name)
            if home is not None and (name != "interpolated" or value is not None):
                tables[home[0]][home[1]] = value
        if self.interpolated is not None:
            tables["adam"]["interpolated"] = self.interpolated
        if solver not in ("ipopt", "adam"):
            raise InputError(f"solver: unknown {solver!r}; choose 'ipopt' or 'adam'")
        optimizer = (
            IpoptConfig(**tables["ipopt"]) if solver == "ipopt" else AdamConfig(**tables["adam"])
        )
        return PlanConfig(SeedConfig(**tables["seed"]), RefineConfig(**tables["refine"]), optimizer)


SOLVER_KEYS = frozenset(f.name for f in fields(TrajoptOptions))  # an old [solver] table
