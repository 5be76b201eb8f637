"""The curve certificate (gdnplan.ccd_curve) on any cubic PPoly: sound at dense samples, jumps
at breakpoints included, and bad curves refused. (Curves of the smooth timing: test_timing.py.)"""

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st
from scipy.interpolate import PPoly

import gdnplan as gp
from gdnplan.ccd_curve import certify_curve
from gdnplan.distance import signed_distance
from gdnplan.errors import InputError

SCENE = gp.make_scene("a")  # planar2 and one 0.3 m square
INSIDE = np.array([-0.3287, 1.5082])  # 1.0 cm inside the square
FAR = np.array([-2.554, 1.8817])  # 0.54 m from it


def _segments(starts: np.ndarray, ends: np.ndarray) -> np.ndarray:
    """(4, n, 2) coefficients of straight pieces starts[k] → ends[k] over unit intervals."""
    c = np.zeros((4, len(starts), 2))
    c[2], c[3] = ends - starts, starts
    return c


# into the square on [0, 1], jumping back out at s = 1 (was certified with 0.153 m)
JUMP_BACK = _segments(np.array([FAR, FAR]), np.array([INSIDE, FAR]))


@st.composite
def cubic_pieces(draw):
    """(4, n, 2) random cubic pieces on unit intervals, each starting where the last ended or
    jumping away from it."""
    rng = np.random.default_rng(draw(st.integers(0, 2**31)))
    n = draw(st.integers(1, 4))
    c = rng.normal(0.0, draw(st.sampled_from([0.1, 0.5, 1.5])), (4, n, 2))
    c[3, 0] = rng.uniform(-3, 3, 2)
    for k in range(1, n):  # p_k(0) = p_{k-1}(1) + a jump
        c[3, k] = c[:, k - 1].sum(axis=0) + rng.normal(0.0, draw(st.sampled_from([0.0, 0.5])), 2)
    return c


@settings(max_examples=40, deadline=None)
@given(cubic_pieces())
@example(JUMP_BACK)
def test_a_certified_curve_keeps_its_bound_at_dense_samples_jumps_included(c):
    curve = PPoly(c, np.arange(c.shape[1] + 1.0))
    cert = certify_curve(SCENE, curve, max_checks=20_000)
    if not cert.ok:
        return
    # every piece's own cubic on its closed interval: the left limits at breakpoints too
    h = np.linspace(0.0, 1.0, 1001)[:, None, None]
    dense = (((c[0] * h + c[1]) * h + c[2]) * h + c[3]).reshape(-1, 2)
    assert np.min(signed_distance(SCENE, dense)) >= cert.lower_bound - 1e-9


def test_a_curve_with_descending_breakpoints_is_refused():
    curve = PPoly(JUMP_BACK, np.array([2.0, 1.0, 0.0]))
    with pytest.raises(InputError, match="increasing breakpoints"):
        certify_curve(SCENE, curve)
