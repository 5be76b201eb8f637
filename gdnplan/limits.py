"""Size limits and value checks of planning settings (every loop is bounded by them).

A setting outside its limit is an :class:`~gdnplan.errors.InputError` naming it and the limit.
Booleans are never numbers, strings never numbers (``margin = true`` is no 1 m).
"""

from __future__ import annotations

import math
import numbers
import sys
from dataclasses import dataclass, fields

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

FLOAT_MAX = sys.float_info.max  # the largest finite float; a larger int is no number (is_number)
MAX_SEED = 2**62  # plan(seed=…): seed i of a call draws the stream seed + i
MAX_IPOPT_NUMBER = 1e20  # Ipopt's own "no limit" default (max_cpu_time, …): larger is refused
# (bound_push = 1e300 overflows inside Ipopt and hangs a factorisation for minutes)


@dataclass(frozen=True)
class IpoptRange:
    """The values an Ipopt number or integer option takes: Ipopt's documented range
    (``print_options_documentation``, Ipopt 3.14), cut at :data:`MAX_IPOPT_NUMBER` (numbers) or
    ``MAX_ITER`` (iteration counts)."""

    kind: type  # float or int
    low: float
    high: float
    open_low: bool = False  # low itself excluded
    open_high: bool = False  # high itself excluded

    def text(self) -> str:
        """The range as an interval, e.g. '(0, 0.5]'."""
        low, high = (f"{x:g}".replace("e+", "e") for x in (self.low, self.high))
        return f"{'(' if self.open_low else '['}{low}, {high}{')' if self.open_high else ']'}"

    def holds(self, value: float) -> bool:
        """``value`` lies in the range."""
        above = value > self.low if self.open_low else value >= self.low
        below = value < self.high if self.open_high else value <= self.high
        return above and below


POSITIVE = IpoptRange(float, 0.0, MAX_IPOPT_NUMBER, open_low=True)  # Ipopt's 0 < x < +inf
NON_NEGATIVE = IpoptRange(float, 0.0, MAX_IPOPT_NUMBER)  # Ipopt's 0 ≤ x < +inf
COUNT = IpoptRange(int, 0, MAX_ITER)  # Ipopt's 0 ≤ n < +inf, cut at gdnplan's iteration cap

# Ipopt options an [ipopt.options] table may set: name -> its range, or the allowed strings
IPOPT_OPTIONS: dict[str, IpoptRange | tuple[str, ...]] = {
    "tol": POSITIVE,
    "acceptable_tol": POSITIVE,
    "acceptable_iter": COUNT,
    "acceptable_obj_change_tol": NON_NEGATIVE,
    "acceptable_constr_viol_tol": POSITIVE,
    "constr_viol_tol": POSITIVE,
    "dual_inf_tol": POSITIVE,
    "compl_inf_tol": POSITIVE,
    "max_iter": COUNT,
    "max_cpu_time": POSITIVE,
    "max_wall_time": POSITIVE,
    "mu_init": POSITIVE,
    "mu_strategy": ("monotone", "adaptive"),
    "mu_oracle": ("probing", "loqo", "quality-function"),
    "hessian_approximation": ("limited-memory",),
    "limited_memory_max_history": COUNT,
    "limited_memory_initialization": ("scalar1", "scalar2", "scalar3", "scalar4", "constant"),
    "limited_memory_update_type": ("bfgs", "sr1"),
    "nlp_scaling_method": ("none", "gradient-based"),
    "bound_push": POSITIVE,
    "bound_frac": IpoptRange(float, 0.0, 0.5, open_low=True),
    "bound_relax_factor": NON_NEGATIVE,
    "warm_start_init_point": ("yes", "no"),
    "warm_start_bound_push": POSITIVE,
    "warm_start_slack_bound_push": POSITIVE,
    "warm_start_mult_bound_push": POSITIVE,
    "linear_solver": ("mumps",),
    "print_level": IpoptRange(int, 0, 12),
}
# string values Ipopt knows that gdnplan cannot run, and why
IPOPT_REFUSED = {
    ("hessian_approximation", "exact"): "the distance rows have first derivatives only (an "
    "exact Hessian would need the model's second derivatives); keep limited-memory",
    ("nlp_scaling_method", "user-scaling"): "gdnplan gives Ipopt no scaling factors",
    ("nlp_scaling_method", "equilibration-based"): "it needs HSL's MC19, which the CasADi "
    "wheels do not ship",
}


def is_number(value) -> bool:
    """An int or float (numpy scalars included), not a bool, that a float holds: an int past
    ±1.8·10³⁰⁸ (a TOML file may hold one) is no number here, since ``math.isfinite`` and numpy
    raise OverflowError on it."""
    if not isinstance(value, (int, float, np.integer, np.floating)) or isinstance(
        value, (bool, np.bool_)
    ):
        return False
    return fits_float(value)


def fits_float(value: object) -> bool:
    """``value`` converts to a float without overflow (an int past ±1.8·10³⁰⁸ does not: it is
    no number for ``math.isfinite``, numpy or torch, which raise OverflowError on it)."""
    return not isinstance(value, int) or -FLOAT_MAX <= value <= FLOAT_MAX


def check_number(value, name: str, low: float = 0.0, strict: bool = False) -> float:
    """A finite number ≥ ``low`` (> with ``strict``), else InputError naming ``name``."""
    ok = is_number(value) and math.isfinite(value)
    ok = ok and (value > low if strict else value >= low)
    if not ok:
        relation = ">" if strict else "≥"
        raise InputError(f"{name}: expected a finite number {relation} {low:g}, got {shown(value)}")
    return float(value)


def shown(value: object, limit: int = 40) -> str:
    """``repr(value)`` cut to ``limit`` characters (huge ints and strings stay one short line;
    a numpy scalar shows as its Python value)."""
    if isinstance(value, np.generic):
        value = value.item()
    try:
        text = repr(value)
    except ValueError:  # an int beyond Python's digit limit for str(), or a list holding one
        if isinstance(value, int):
            return f"an integer of about {value.bit_length() * 0.30103:.0f} digits"
        return f"a {type(value).__name__} holding an integer too long to show"
    except RecursionError:  # lists nested deeper than repr follows
        return f"a {type(value).__name__} nested too deeply to show"
    return text if len(text) <= limit else f"{text[:limit]}…"


def floor_text(lower_bound: float, places: int = 4) -> str:
    """A proven lower bound (m) as signed text with ``places`` decimals, rounded DOWN (toward
    −inf), so the printed bound never claims more than was proven: 0.72638 m shows as
    "+0.7263", not "+0.7264" (``:+.4f`` rounds to nearest and claimed 0.02 mm more). A bound
    within 10⁻⁶ of a decimal step below it shows as that step (0.0123 stays "+0.0123": binary
    floats store it a hair under), a claim off by at most 10⁻⁶ of the last place. Non-finite
    values and magnitudes ≥ 10¹² (no float digits left to round) show as Python formats them."""
    if not math.isfinite(lower_bound) or abs(lower_bound) >= 1e12:
        return f"{lower_bound:+.{places}f}"
    scale = 10**places
    return f"{math.floor(lower_bound * scale + 1e-6) / scale:+.{places}f}"


def plain_fields(settings: object) -> None:
    """Each numpy scalar field of the (frozen) dataclass ``settings`` replaced by its Python
    value (``np.int8(50)`` → 50, ``np.float32(0.5)`` → 0.5): numpy integers keep their width
    in arithmetic, so ``interpolated = np.int8(50)`` made int8 check-point counts that the
    refine rounds doubled past 127 to negative (the check points vanished), and numpy values
    do not serialise to JSON."""
    for item in fields(settings):
        value = getattr(settings, item.name)
        if isinstance(value, np.generic):
            object.__setattr__(settings, item.name, value.item())


def read_only(value) -> np.ndarray:
    """A read-only float64 copy of ``value``: geometry that caches (coal shapes, lever arms,
    checkers) is built from such arrays, so an in-place change (``obstacle += offset``) raises
    instead of leaving a certificate to run on the geometry as it was."""
    out = np.array(value, dtype=float)
    out.setflags(write=False)
    return out


def is_integer(value: object) -> bool:
    """An int or numpy integer (any :class:`numbers.Integral`), not a bool."""
    return isinstance(value, numbers.Integral) and not isinstance(value, bool)


def check_int(value: object, name: str, low: int, high: int | None = None, note: str = "") -> int:
    """``value`` as an int when it is an integer (numpy integers too, bools never) in
    [``low``, ``high``] (``high`` None: no upper bound), else InputError naming ``name`` and
    the allowed range, followed by ``note`` (why the range) in brackets when given."""
    if not is_integer(value) or value < low or (high is not None and value > high):
        allowed = f"≥ {low}" if high is None else f"in [{low}, {high}]"
        why = f" ({note})" if note else ""
        raise InputError(f"{name}: expected an integer {allowed}{why}, got {shown(value)}")
    return int(value)


def check_ipopt(options) -> None:
    """InputError unless ``options`` maps known Ipopt option names (:data:`IPOPT_OPTIONS`) to
    values of their type in their range (a bad name or value makes Ipopt stop with
    Invalid_Option and print its option help to stdout)."""
    if not isinstance(options, dict):
        raise InputError(f"ipopt: expected a table of Ipopt options, got {shown(options)}")
    for key, value in options.items():
        kind = IPOPT_OPTIONS.get(key)
        where = f"ipopt.{key}"
        if kind is None:
            raise InputError(
                f"{where}: unknown or unsupported option; allowed: {sorted(IPOPT_OPTIONS)}"
            )
        if isinstance(kind, tuple):  # a string option (a list or array value is no string)
            if isinstance(value, str) and (key, value) in IPOPT_REFUSED:
                raise InputError(
                    f"{where}: {value!r} is not supported: {IPOPT_REFUSED[key, value]}; "
                    f"choose one of {list(kind)}"
                )
            if not isinstance(value, str) or value not in kind:
                raise InputError(f"{where}: expected one of {list(kind)}, got {shown(value)}")
        else:
            check_ipopt_number(value, where, kind)


def check_ipopt_number(value, where: str, allowed: IpoptRange) -> None:
    """InputError naming ``where`` and the range unless ``value`` is a number (an integer for
    an integer option) in ``allowed``."""
    what = "an integer" if allowed.kind is int else "a number"
    typed = (is_integer(value) and fits_float(value)) if allowed.kind is int else is_number(value)
    if not typed or not math.isfinite(value) or not allowed.holds(value):
        raise InputError(f"{where}: expected {what} in {allowed.text()}, got {shown(value)}")
