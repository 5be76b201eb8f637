"""The shared number checks of gdnplan.limits: a Python int too large for a float (a TOML file
or a caller may hold one) is no number. Every numeric setting refuses it with an InputError
naming the setting, never numpy's or math's OverflowError, and a message never fails on an
integer of more digits than ``repr`` shows (Python's 4300-digit limit)."""

from __future__ import annotations

import sys
from dataclasses import fields

import numpy as np
import pytest
from hypothesis import example, given
from hypothesis import strategies as st

import gdnplan as gp
from gdnplan.errors import InputError, ProblemFileError
from gdnplan.limits import check_ipopt, check_number, fits_float, floor_text, is_number, shown
from gdnplan.rrt import rrt_connect
from gdnplan.timing_checks import limit_vector

FLOAT_MAX = sys.float_info.max
# ints past the float range: just past it, far past it, past repr's digit limit
HUGE = st.one_of(
    st.integers(min_value=int(FLOAT_MAX) + 2**971, max_value=10**400),
    st.sampled_from([10**309, -(10**309), 10**5000]),
)
NUMBER_FIELDS = {  # config -> its number (float) fields
    gp.SeedConfig: ("time_budget", "rrt_time", "rrt_step", "rrt_clearance"),
    gp.RefineConfig: ("clearance_buffer",),
    gp.IpoptConfig: ("link_cap", "tol", "obj_change_tol"),
    gp.AdamConfig: ("lr", "c", "eps", "stop"),
}


@given(HUGE)
@example(10**5000)
def test_ints_past_the_float_range_are_no_numbers(value):
    assert not is_number(value) and not fits_float(value)
    with pytest.raises(InputError, match=r"^m: expected a finite number ≥ 0, got ") as e:
        check_number(value, "m")
    assert str(e.value).endswith(shown(value))


def test_shown_of_a_list_holding_an_overlong_int():
    """repr raised ValueError and shown then called bit_length on the list."""
    assert shown([10**5000, 0.0]) == "a list holding an integer too long to show"


@pytest.mark.parametrize("value", [0, 2**1023, int(FLOAT_MAX), -int(FLOAT_MAX), np.int64(-5)])
def test_ints_within_the_float_range_stay_numbers(value):
    assert is_number(value) and check_number(abs(value), "m") == float(abs(value))


@given(value=HUGE, config=st.sampled_from(sorted(NUMBER_FIELDS, key=lambda c: c.__name__)))
@example(value=10**5000, config=gp.AdamConfig)
def test_every_number_setting_refuses_them(value, config):
    for name in NUMBER_FIELDS[config]:
        with pytest.raises(InputError, match=rf"^{name}: expected a finite number"):
            config(**{name: value})


@given(HUGE)
@example(10**400)
def test_problem_fields_refuse_them(value):
    base = gp.Problem.from_toml("planar2_square")
    kept = {f.name: getattr(base, f.name) for f in fields(base)}
    for name in ("margin", "max_step", "goal_tolerance", "clearance"):
        with pytest.raises(InputError, match=rf"^options\.{name}: expected a finite number"):
            gp.Problem(**{**kept, name: value})
    for name, size in (("start", 2), ("goal", 2)):
        with pytest.raises(InputError, match=rf"^{name}\.q: expected a list of {size} numbers"):
            gp.Problem(**{**kept, name: [value, 0.0]})
    no_goal = {**kept, "goal": None, "goal_position": [value, 0.0]}
    with pytest.raises(InputError, match=r"^goal\.position: expected a list of 2 numbers"):
        gp.Problem(**no_goal)


@pytest.mark.parametrize("value", [10**400, 10**5000], ids=["400 digits", "5000 digits"])
def test_ipopt_options_refuse_them(value):
    for option, what in (("tol", "a number"), ("max_iter", "an integer")):
        with pytest.raises(InputError, match=rf"^ipopt\.{option}: expected {what} in "):
            check_ipopt({option: value})


@pytest.mark.parametrize("value", [["adaptive"], np.array(["adaptive"]), {"a": 1}, 3])
def test_ipopt_string_options_refuse_non_strings(value):
    """A list value raised TypeError (unhashable) and an array numpy's truth-value error."""
    with pytest.raises(InputError, match=r"^ipopt\.mu_strategy: expected one of \['monotone'"):
        check_ipopt({"mu_strategy": value})


@pytest.mark.parametrize(
    "value",
    [10**400, np.array(4.0), np.ones((1, 2)), np.ones((2, 1))],
    ids=["huge int", "0-d array", "(1, 2) array", "(2, 1) array"],
)
def test_time_limits_refuse_them(value):
    """A 0-d array raised TypeError (iteration over a 0-d array), a huge int OverflowError."""
    with pytest.raises(InputError, match=r"^max_acceleration: expected a number or 2 numbers"):
        limit_vector(value, 2, "max_acceleration", "rad/s²")


def test_rrt_settings_refuse_them():
    scene = gp.make_scene("a")
    q0, q1 = np.array([2.006, -0.737]), np.array([1.448, -2.722])
    with pytest.raises(InputError, match=r"^rrt_step: expected a finite number > 0"):
        rrt_connect(scene, q0, q1, step=10**400)


def test_problem_file_of_an_overlong_integer(tmp_path):
    """tomllib raised Python's digit-limit ValueError (an internal error on the CLI)."""
    path = tmp_path / "p.toml"
    path.write_text(
        '[robot]\nname = "planar2"\n[scene]\ngenerator = "a"\n[start]\nq = [2.006, -0.737]\n'
        f"[goal]\nq = [1.448, -2.722]\n[options]\nmargin = 1{'0' * 5000}\n"
    )
    with pytest.raises(ProblemFileError, match=r"p\.toml: a number too long to read"):
        gp.Problem.from_toml(path)


@given(st.floats(min_value=-1e6, max_value=1e6, allow_nan=False))
@example(0.7263805400037253)  # a held-out plan's proven bound: ":+.4f" printed "+0.7264"
@example(-0.00004)  # ":+.4f" printed "-0.0000", above the bound
@example(0.0123)  # stored a hair under 0.0123: still shows "+0.0123"
def test_floor_text_never_claims_more_than_the_bound(x):
    """A printed lower bound is rounded down: at most 10⁻⁶ of the last place above the value
    (the floats a hair under a decimal step), never a rounding step above it."""
    shown_value = float(floor_text(x))
    assert shown_value <= x + 1e-6 * 1e-4 * (1 + abs(x))
    assert shown_value > x - 1e-4 - 1e-9 * (1 + abs(x))


def test_floor_text_keeps_exact_steps_and_non_finite_values():
    assert floor_text(0.0123) == "+0.0123" and floor_text(0.02) == "+0.0200"
    assert floor_text(0.7263805400037253) == "+0.7263"
    assert floor_text(-0.00004) == "-0.0001"
    assert floor_text(float("inf")) == "+inf" and floor_text(1e300) == f"{1e300:+.4f}"
