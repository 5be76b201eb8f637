"""[ipopt.options]: every allowed option is checked against Ipopt's documented range (Ipopt 3.14's
``print_options_documentation``, written out here independently of gdnplan.limits); a value
inside solves cleanly, a value outside is an InputError naming the option and its range."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from gdnplan.errors import GdnplanError, InputError
from gdnplan.limits import IPOPT_OPTIONS, IpoptRange, check_ipopt
from gdnplan.models import CoalModel
from gdnplan.trajopt import IpoptConfig, Problem, straight_line
from gdnplan.trajopt.ipopt import SOLVER_ERRORS
from gdnplan.trajopt.transcription import _Transcription

SQUARE = Path(__file__).parent.parent / "problems" / "planar2_square.toml"
INF = math.inf
# Ipopt 3.14.19's print_options_documentation: name -> (low, high, low open, high open, int)
DOCUMENTED = {
    "tol": (0, INF, True, True, False),
    "acceptable_tol": (0, INF, True, True, False),
    "acceptable_iter": (0, INF, False, True, True),
    "acceptable_obj_change_tol": (0, INF, False, True, False),
    "acceptable_constr_viol_tol": (0, INF, True, True, False),
    "constr_viol_tol": (0, INF, True, True, False),
    "dual_inf_tol": (0, INF, True, True, False),
    "compl_inf_tol": (0, INF, True, True, False),
    "max_iter": (0, INF, False, True, True),
    "max_cpu_time": (0, INF, True, True, False),
    "max_wall_time": (0, INF, True, True, False),
    "mu_init": (0, INF, True, True, False),
    "limited_memory_max_history": (0, INF, False, True, True),
    "bound_push": (0, INF, True, True, False),
    "bound_frac": (0, 0.5, True, False, False),
    "bound_relax_factor": (0, INF, False, True, False),
    "warm_start_bound_push": (0, INF, True, True, False),
    "warm_start_slack_bound_push": (0, INF, True, True, False),
    "warm_start_mult_bound_push": (0, INF, True, True, False),
    "print_level": (0, 12, False, False, True),
}
NUMERIC = sorted(k for k, v in IPOPT_OPTIONS.items() if isinstance(v, IpoptRange))


def within_ipopt(name: str, value) -> bool:
    """``value`` is in Ipopt's documented range of ``name`` (and of its type)."""
    low, high, open_low, open_high, integer = DOCUMENTED[name]
    if integer and (isinstance(value, bool) or not isinstance(value, int)):
        return False
    if isinstance(value, bool) or not math.isfinite(value):
        return False
    above = value > low if open_low else value >= low
    below = value < high if open_high else value <= high
    return above and below


def test_every_numeric_option_has_a_documented_range():
    assert set(NUMERIC) == set(DOCUMENTED)


@pytest.fixture(scope="module")
def tiny():
    p = Problem.from_toml("planar2_square")
    return Problem(p.scene, p.start, goal=p.goal, waypoints=4)


def solve(problem: Problem, options: dict) -> str:
    """Ipopt's status on the tiny problem with ``options`` over a short budget."""
    base = {"max_wall_time": 2.0, "max_iter": 30}
    opts = IpoptConfig(options={**base, **options}, per_link=False)
    splits = np.full(problem.waypoints - 1, 3)
    nlp = _Transcription(problem, CoalModel(), problem.goal, opts, splits, problem.margin)
    _, stats = nlp.solve(straight_line(problem.start, problem.goal, problem.waypoints))
    return stats["return_status"]


values = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True),
    st.integers(-5, 20_000),
    st.sampled_from([0, 0.5, 0.50001, 12, 13, 99, 1e20, 1.1e20, 1e300, -0.0, 5.0, True]),
)


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(name=st.sampled_from(NUMERIC), value=values)
def test_an_option_value_is_refused_outside_ipopts_range_and_solves_inside(tiny, name, value):
    try:
        check_ipopt({name: value})
    except InputError as e:
        assert f"ipopt.{name}" in str(e) and IPOPT_OPTIONS[name].text() in str(e)
        return
    assert within_ipopt(name, value), f"{name} = {value!r} accepted outside Ipopt's range"
    assert abs(value) <= 1e20  # gdnplan's cap on top of Ipopt's range
    if name in ("max_wall_time", "max_cpu_time"):
        value = max(value, 1e-3) if value < 2.0 else 2.0  # keep the solve short
    if name == "print_level":
        value = 0  # keep the test's stdout clean (print_level > 0: tests/test_cli_plan_ipopt.py)
    status = solve(tiny, {name: value})
    assert status not in SOLVER_ERRORS and not status.startswith("exception"), status


@pytest.mark.parametrize(
    "name, value, words",
    [
        ("print_level", 99, "[0, 12]"),
        ("print_level", -1, "[0, 12]"),
        ("bound_frac", 5.0, "(0, 0.5]"),
        ("bound_frac", 0, "(0, 0.5]"),
        ("bound_push", 1e300, "(0, 1e20]"),
        ("bound_push", math.nan, "(0, 1e20]"),
        ("max_iter", 2.0, "integer"),
        ("tol", True, "number"),
        ("mu_init", "0.1", "number"),
        ("hessian_approximation", "exact", "first derivatives"),
        ("nlp_scaling_method", "equilibration-based", "MC19"),
        ("nlp_scaling_method", "user-scaling", "scaling factors"),
        ("linear_solver", "ma27", "mumps"),
    ],
)
def test_bad_values_are_refused_naming_the_option_and_its_range(name, value, words):
    with pytest.raises(InputError) as info:
        check_ipopt({name: value})
    assert f"ipopt.{name}" in str(info.value) and words in str(info.value)


@pytest.mark.parametrize(
    "name", sorted(k for k, v in IPOPT_OPTIONS.items() if isinstance(v, tuple))
)
def test_every_allowed_string_value_solves(tiny, name):
    for value in IPOPT_OPTIONS[name]:
        status = solve(tiny, {name: value})
        assert status not in SOLVER_ERRORS and not status.startswith("exception"), (name, value)


@pytest.mark.parametrize(
    "line, match",
    [
        ("bound_frac = 5.0", r"ipopt\.bound_frac.*\(0, 0\.5\]"),
        ("print_level = 99", r"ipopt\.print_level.*\[0, 12\]"),
        ('hessian_approximation = "exact"', r"ipopt\.hessian_approximation.*not supported"),
        ("bound_push = 1e300", r"ipopt\.bound_push.*\(0, 1e20\]"),
    ],
)
def test_a_problem_file_with_an_out_of_range_option_is_one_named_error(tmp_path, line, match):
    path = tmp_path / "p.toml"
    path.write_text(SQUARE.read_text() + f"\n[ipopt.options]\n{line}\n", encoding="utf-8")
    with pytest.raises(GdnplanError, match=match):
        Problem.from_toml(path)
