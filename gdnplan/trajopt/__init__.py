"""Trajectory optimisation: Problem, Plan, Ipopt direct transcription, the paper's Adam baseline.

Direct transcription over T waypoints Q = (q_0, …, q_{T−1}), q_0 = start, q_{T−1} = goal:

    minimise    Σ_t ‖q_{t+1} − q_t‖²                                   (the paper's path cost)
    subject to  lower ≤ q_t ≤ upper,   |q_{t+1} − q_t| ≤ max_step      (joint, step limits)
                d(p_k) ≥ m_c              at the check points p = q_t + i/n_t (q_{t+1} − q_t),
                                          i = 0 … n_t − 1, of every segment t (n_t = M + 1 first),
                                          except the fixed start and goal themselves,
                                          m_c = max(margin, c + clearance_buffer)

with d the overall or per-link distance of any DistanceModel (one batched call through
:class:`~gdnplan.casadi_bridge.DistanceCallback`) and c the certified clearance
(:attr:`Problem.certified_clearance`: the margin unless ``Problem.clearance`` asks for less),
the clearance the certificate must prove on the whole continuous path for a plan to succeed.
The check points sit ``clearance_buffer`` (2 mm) above c because Ipopt leaves active rows a
hair inside their bound, which a certificate at exactly that bound rejects. The start and goal
rows would be constants: coal checks both when the problem is made (d > margin), and a learned
model that rates one of them below the margin (the held stick 1.75 cm above its shelf) would
only make the NLP infeasible.
Continuous collision (the CCD certificate): after each solve, :func:`gdnplan.ccd.certify_path`
checks the continuous motion with coal by conservative advancement at the clearance c; every
waypoint segment it cannot certify gets twice as many check points (n_t ← 2 n_t) — and, for
a learned model, the bound there and on ``raise_window`` segments either side is raised to
the margin plus the model's observed overestimate (the largest seen so far, not a sum over
rounds) — and Ipopt re-solves from the current path, for ``RefineConfig.rounds`` rounds.
(The certificate as NLP rows, d(p_k) + d(p_{k+1}) ≥ δ(p_k, p_{k+1}) + 2·margin, was tried and
dropped: at 3 check points per segment δ reaches ~1 m on seed paths, the rows are infeasible
and Ipopt runs to its iteration cap.) Ipopt uses a limited-memory Hessian and starts from the
straight line when it is certified free (then it is already optimal and returned as is) or
from seed paths (:mod:`gdnplan.trajopt.seeds`: RRT-Connect, a via point, or any registered
kind), replacing a seed whose path ends uncertified; with ``SeedConfig.count`` > 1 (or a
``time_budget``) it refines several seeds and returns the certified path of least path cost.
Then (:mod:`gdnplan.trajopt.polish`) the polish re-solves from that path with tighter stops,
more check points and buffers of 0.5 and 0.2 mm, each result kept when certified and cheaper;
when no seed was certified, the repair re-solves from the last path with more check points and
a wider buffer. A plan succeeds only when
:func:`gdnplan.ccd.certify_path` proves with coal that the whole returned path keeps d > c
(``Plan.min_distance`` is that proven bound) and the goal is reached — never on the solver's
word alone.
"""

# ruff: noqa: F401  (the package's names, re-exported from the modules that define them)
from __future__ import annotations

import warnings

from ..ccd import verify_path
from .adam import collision_cost
from .check_points import distance_bounds, model_overestimate, straight_line
from .config import (
    CONFIG_TABLES,
    INITIAL_GUESSES,
    AdamConfig,
    IpoptConfig,
    PlanConfig,
    RefineConfig,
    SeedConfig,
)
from .ik import first_joint_barrier, tip_point, tip_position, tip_reach
from .ipopt import SOLVER_ERRORS
from .options import ADAM_INTERPOLATED, IPOPT_INTERPOLATED, OLD_KEYS, SOLVER_KEYS, TrajoptOptions
from .planner import checked, numeric_ik, plan, plan_config, resolve_model
from .problem import Problem
from .problem_file import (
    CONFIG_KEYS,
    GOAL_KEYS,
    OPTION_KEYS,
    START_KEYS,
    TOP_KEYS,
    ProblemTables,
    problem_start,
    problem_tables,
    read_problem_file,
)
from .result import Plan, path_cost
from .seeds import SEED_KINDS, SeedInfo, SeedRequest, register_seed_kind
from .transcription import WARM_START_OPTIONS

# private helpers that the CLI and tests/test_trajopt.py import from here
from .check_points import _check_point_raise, _near_segments, _path_parameters  # isort: skip
from .problem_file import _no_unknown, _vector  # isort: skip
from .transcription import _Transcription  # isort: skip

__all__ = [
    "AdamConfig",
    "IpoptConfig",
    "Plan",
    "PlanConfig",
    "Problem",
    "RefineConfig",
    "SeedConfig",
    "SeedInfo",
    "SeedRequest",
    "TrajoptOptions",
    "collision_cost",
    "distance_bounds",
    "first_joint_barrier",
    "numeric_ik",
    "path_cost",
    "plan",
    "plan_config",
    "register_seed_kind",
    "straight_line",
    "tip_position",
    "verify_path",
]

_DEPRECATED = {"solve_ik": "numeric_ik"}  # old name -> its new name in this package


def __getattr__(name: str) -> object:
    """Deprecated names: warn (DeprecationWarning naming the new one), then return it."""
    if name in _DEPRECATED:
        new = _DEPRECATED[name]
        warnings.warn(
            f"gdnplan.trajopt.{name} is deprecated; use gdnplan.trajopt.{new} (the numeric IK "
            "of a goal position; the UR5e's exact IK of a tcp pose is gdnplan.ur5e.analytic_ik)",
            DeprecationWarning,
            stacklevel=2,
        )
        return globals()[new]
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
