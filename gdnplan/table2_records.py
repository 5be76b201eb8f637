"""Table II's records: one solve (:class:`Record`), one row's aggregates (:class:`Row`,
:func:`summarize`), the settings, methods and solvers, and the paper's figures (:data:`PAPER`)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

SETTINGS = ("b", "d", "fetch")
METHODS = ("GraphDistNet", "ClearanceNet", "DiffCo", "coal")
SOLVERS = ("ipopt", "adam")
# Paper's Table II (GraphDistNet, ClearanceNet, DiffCo with Adam): (mean time s, cost, success)
PAPER = {
    "b": {
        "DiffCo": (0.9304, 23.7657, 0.95),
        "ClearanceNet": (1.7300, 24.9018, 1.0),
        "GraphDistNet": (1.9522, 24.4297, 1.0),
    },
    "d": {
        "DiffCo": (28.8247, 99.0850, 0.95),
        "ClearanceNet": (10.9816, 72.3153, 0.4),
        "GraphDistNet": (16.2682, 65.0297, 0.9),
    },
    "fetch": {
        "DiffCo": (0.6364, 3.9e5, 0.4),
        "ClearanceNet": (1.9603, 5.5e5, 0.3),
        "GraphDistNet": (3.2982, 9.0e5, 0.7),
    },
}


@dataclass(frozen=True)
class Record:
    """One solve of one problem.

    Attributes:
        setting, method, solver: which row of the table.
        problem: index of the problem in its setting.
        success: the coal certificate proved the margin on the whole path and the goal is
            reached.
        time: wall time of :func:`gdnplan.trajopt.plan` (s), model preparation excluded.
        prep_time: time to make the model for this problem (s): DiffCo's training, else 0.
        path_cost: Σ_t ‖q_{t+1} − q_t‖² (rad²).
        min_distance: certified coal clearance of the path (m): > the margin on success.
        status: the solver's status; reason: why it failed (or which attempt succeeded).
    """

    setting: str
    method: str
    solver: str
    problem: int
    success: bool
    time: float
    prep_time: float
    path_cost: float
    min_distance: float
    status: str
    reason: str


@dataclass(frozen=True)
class Row:
    """Aggregates of one (setting, method, solver) over its problems."""

    setting: str
    method: str
    solver: str
    n: int
    successes: int
    mean_time: float
    median_time: float
    mean_prep: float
    mean_cost: float | None  # over the problems every row of the setting solved
    common: int  # how many such problems


def summarize(records: list[Record]) -> list[Row]:
    """One :class:`Row` per (setting, method, solver), path cost on the commonly solved."""
    rows = []
    for setting in dict.fromkeys(r.setting for r in records):
        mine = [r for r in records if r.setting == setting]
        keys = list(dict.fromkeys((r.method, r.solver) for r in mine))
        solved = {
            k: {r.problem for r in mine if (r.method, r.solver) == k and r.success} for k in keys
        }
        common = set.intersection(*solved.values()) if solved else set()
        for method, solver in keys:
            group = [r for r in mine if (r.method, r.solver) == (method, solver)]
            costs = [r.path_cost for r in group if r.problem in common]
            rows.append(
                Row(
                    setting,
                    method,
                    solver,
                    len(group),
                    sum(r.success for r in group),
                    float(np.mean([r.time for r in group])),
                    float(np.median([r.time for r in group])),
                    float(np.mean([r.prep_time for r in group])),
                    float(np.mean(costs)) if costs else None,
                    len(common),
                )
            )
    return rows


__all__ = ["METHODS", "PAPER", "SETTINGS", "SOLVERS", "Record", "Row", "summarize"]
