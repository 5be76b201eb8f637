"""Size limits and value checks of planning settings (every loop is bounded by them).

A setting outside its limit is an :class:`~gdnplan.errors.InputError` naming it and the limit.
Booleans are never numbers, strings never numbers (``margin = true`` is no 1 m).
"""

from __future__ import annotations

import math

import numpy as np

from .errors import InputError

MAX_WAYPOINTS = 500  # Problem.waypoints
MAX_INTERPOLATED = 50  # IpoptConfig/AdamConfig.interpolated: check points inside one segment
MAX_CHECK_POINTS = 20_000  # (waypoints − 1) · (interpolated + starts) of a first solve
MAX_REFINE_ROUNDS = 8  # each doubles the check points of a rejected segment
MAX_STARTS = 50  # SeedConfig.starts
MAX_SEEDS = 50  # SeedConfig.count: seed paths refined in one plan call
MAX_TIME_BUDGET = 3600.0  # s, SeedConfig.time_budget of one plan call
MAX_ITER = 10_000  # Ipopt iterations per attempt
MAX_ADAM_ITERATIONS = 100_000
MAX_RRT_TIME = 600.0  # s, one RRT-Connect run
MAX_DRAWS = 1000  # BatchedGraphDistNet draws: each is a whole pass over the samples
MAX_TIMED_SAMPLES = 1_000_000  # TimedTrajectory.sample: time samples of one call

# Ipopt options an [ipopt.options] table may set: name -> float, int, or the allowed strings
IPOPT_OPTIONS: dict[str, type | tuple[str, ...]] = {
    "tol": float,
    "acceptable_tol": float,
    "acceptable_iter": int,
    "acceptable_obj_change_tol": float,
    "acceptable_constr_viol_tol": float,
    "constr_viol_tol": float,
    "dual_inf_tol": float,
    "compl_inf_tol": float,
    "max_iter": int,
    "max_cpu_time": float,
    "max_wall_time": float,
    "mu_init": float,
    "mu_strategy": ("monotone", "adaptive"),
    "mu_oracle": ("probing", "loqo", "quality-function"),
    "hessian_approximation": ("exact", "limited-memory"),
    "limited_memory_max_history": int,
    "limited_memory_initialization": ("scalar1", "scalar2", "scalar3", "scalar4", "constant"),
    "limited_memory_update_type": ("bfgs", "sr1"),
    "nlp_scaling_method": ("none", "user-scaling", "gradient-based", "equilibration-based"),
    "bound_push": float,
    "bound_frac": float,
    "bound_relax_factor": float,
    "warm_start_init_point": ("yes", "no"),
    "warm_start_bound_push": float,
    "warm_start_slack_bound_push": float,
    "warm_start_mult_bound_push": float,
    "linear_solver": ("mumps",),
    "print_level": int,
}


def is_number(value) -> bool:
    """An int or float (numpy scalars included), not a bool."""
    return isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(
        value, (bool, np.bool_)
    )


def check_number(value, name: str, low: float = 0.0, strict: bool = False) -> float:
    """A finite number ≥ ``low`` (> with ``strict``), else InputError naming ``name``."""
    ok = is_number(value) and math.isfinite(value)
    ok = ok and (value > low if strict else value >= low)
    if not ok:
        relation = ">" if strict else "≥"
        raise InputError(f"{name}: expected a finite number {relation} {low:g}, got {value!r}")
    return float(value)


def check_int(value, name: str, low: int, high: int) -> int:
    """An integer in [low, high], else InputError naming ``name`` and the limit."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise InputError(f"{name}: expected an integer in [{low}, {high}], got {value!r}")
    if not low <= value <= high:
        raise InputError(f"{name}: {value} is outside [{low}, {high}] (the limit)")
    return int(value)


def check_ipopt(options) -> None:
    """InputError unless ``options`` maps known Ipopt option names (:data:`IPOPT_OPTIONS`) to
    values of their type (a bad name or value makes CasADi raise and Ipopt print to stdout)."""
    if not isinstance(options, dict):
        raise InputError(f"ipopt: expected a table of Ipopt options, got {options!r}")
    for key, value in options.items():
        kind = IPOPT_OPTIONS.get(key)
        where = f"ipopt.{key}"
        if kind is None:
            raise InputError(
                f"{where}: unknown or unsupported option; allowed: {sorted(IPOPT_OPTIONS)}"
            )
        if isinstance(kind, tuple):
            if value not in kind:
                raise InputError(f"{where}: expected one of {list(kind)}, got {value!r}")
        elif kind is int:
            check_int(value, where, 0, 10**9)
        else:
            check_number(value, where, 0.0, strict=True)
