"""Checks of the fields of the models' architecture configs (a weights card's ``config``).

A card's config is as much input as the tensors: its sizes build the network, its lengths
normalise coordinates in float32, its run-time counts (soft partners, probe points) size the
buffers of every inference call. So every field is checked for its type and range before a
network is built (InputError naming the field; :func:`gdnplan.models.checks.card_config` adds
the card's file name):

* integers are ints (not floats, not bools) within their bounds
  (:func:`gdnplan.limits.check_int`, imported here with :func:`~gdnplan.limits.shown`);
* flags are ``true`` / ``false`` only (not ``"false"``, not 0 / 1);
* choices are strings from their set;
* layer widths are lists of positive ints, at most :data:`MAX_DEPTH` of them;
* real numbers are finite ints or floats (not bools) within their bounds;
* points (``origin``) are lists of exactly the dimension's finite numbers.

The bounds (below) keep every value float32-safe, e.g. a coordinate (m) divided by
``scale`` (m) stays well inside float32's range for coordinates up to :data:`MAX_LENGTH`, and
leave far more room than any trained network uses (the shipped cards: scale 1.1–2.1 m,
origin 0, at most 4 layers of 32 features, 4 partners, 5 probe pieces).
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Sequence

import numpy as np

from .. import flags
from ..errors import InputError
from ..limits import check_int, fits_float, shown

MIN_LENGTH, MAX_LENGTH = 1e-3, 1e3  # m: scale, length, |origin| (and correction bands below)
MAX_LAYERS = 64  # message-passing layers
MAX_WIDTH = 4096  # feature size of any layer
MAX_DEPTH = 16  # hidden layers of any MLP
MAX_CROSS_K = 64  # soft partners: buffers of (batch × nodes × (k + 1)) per layer
MAX_PROBE_SPLIT = 32  # pieces per ring edge: (batch × edges × pieces) probe points per call
MIN_TEMPERATURE, MAX_TEMPERATURE = 1e-12, 1e6  # τ, τ_m (normalised units; stored as a log)


def _is_real(value: object) -> bool:
    """A real number a float holds (not a bool; an int past ±1.8·10³⁰⁸ overflows)."""
    return isinstance(value, numbers.Real) and not isinstance(value, bool) and fits_float(value)


def check_real(name: str, value: object, low: float, high: float, unit: str = "") -> float:
    """``value`` as a float when it is a finite number (not a bool) in [``low``, ``high``]."""
    if not _is_real(value) or not math.isfinite(value) or not low <= value <= high:
        raise InputError(
            f"{name}: expected a finite number in [{low:g}, {high:g}]{unit}, got {shown(value)}"
        )
    return float(value)


def check_flag(name: str, value: object) -> bool:
    """``value`` as a Python bool when it is True or False (JSON ``true`` / ``false``, a numpy
    bool; not 0 / 1, not a string): :func:`gdnplan.flags.check_flag`."""
    return flags.check_flag(value, name, lowercase=True)


def check_choice(name: str, value: object, choices: Sequence[str]) -> str:
    """``value`` when it is one of the strings ``choices``."""
    if not isinstance(value, str) or value not in choices:
        raise InputError(f"{name}: expected one of {list(choices)}, got {shown(value)}")
    return value


def check_widths(name: str, value: object, depth: int = MAX_DEPTH) -> tuple[int, ...]:
    """``value`` as a tuple when it is a list of at most ``depth`` ints in 1 … MAX_WIDTH."""
    if isinstance(value, (str, bytes)) or not isinstance(value, Sequence) or len(value) > depth:
        raise InputError(
            f"{name}: expected a list of at most {depth} layer widths, got {shown(value)}"
        )
    return tuple(check_int(v, f"{name}[{i}]", 1, MAX_WIDTH) for i, v in enumerate(value))


def check_point(name: str, value: object, dim: int, bound: float = MAX_LENGTH) -> tuple:
    """``value`` as a tuple of floats when it is a list of ``dim`` finite numbers, each of
    magnitude ≤ ``bound`` (m)."""
    if isinstance(value, np.ndarray) and value.ndim == 1:
        value = value.tolist()
    if isinstance(value, (str, bytes)) or not isinstance(value, Sequence) or len(value) != dim:
        raise InputError(f"{name}: expected a list of {dim} numbers (m), got {shown(value)}")
    return tuple(check_real(f"{name}[{i}]", v, -bound, bound, " m") for i, v in enumerate(value))
