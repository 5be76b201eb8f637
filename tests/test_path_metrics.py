"""gdnplan.path_metrics: arc length, arc-length resampling and the resampled path cost, against
analytic paths and the properties the module docstring states."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from gdnplan.errors import InputError
from gdnplan.path_metrics import path_length, resample_arc_length, resampled_cost

finite = st.floats(-3.0, 3.0, allow_nan=False, allow_infinity=False)


@given(
    a=arrays(float, 4, elements=finite),
    b=arrays(float, 4, elements=finite),
    cuts=st.lists(st.floats(0.0, 1.0), max_size=12),
    n=st.integers(2, 40),
)
def test_straight_line_is_invariant_to_its_discretisation(a, b, cuts, n):
    """However a straight segment a → b is split (repeated points included), the resampled
    points are a + i/(n−1) (b − a) and the cost is L² / (n − 1)."""
    s = np.sort(np.concatenate([[0.0, 1.0], cuts]))
    path = a + s[:, None] * (b - a)
    length = float(np.linalg.norm(b - a))
    expected = a + np.linspace(0.0, 1.0, n)[:, None] * (b - a)
    np.testing.assert_allclose(resample_arc_length(path, n), expected, atol=1e-9)
    assert resampled_cost(path, n) == pytest.approx(length**2 / (n - 1), rel=1e-9, abs=1e-12)
    assert path_length(path) == pytest.approx(length, rel=1e-9, abs=1e-12)


def test_l_shaped_path_exact_values():
    """(0,0) → (1,0) → (1,1), L = 2. n = 3 hits the corner: cost 2. n = 4 (spacing 2/3):
    points (0,0), (2/3,0), (1,1/3), (1,1): cost 4/9 + 2/9 + 4/9 = 10/9."""
    path = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]])
    assert path_length(path) == pytest.approx(2.0)
    assert resampled_cost(path, 3) == pytest.approx(2.0)
    np.testing.assert_allclose(
        resample_arc_length(path, 4), [[0, 0], [2 / 3, 0], [1, 1 / 3], [1, 1]], atol=1e-12
    )
    assert resampled_cost(path, 4) == pytest.approx(10 / 9)


@pytest.mark.parametrize("sides", [3, 8, 50])
def test_regular_polygon_arc(sides):
    """The vertices of a regular polygon inscribed in a circle of radius r, arc angle θ, are
    equally spaced in arc length: resampled to sides + 1 points they come back, cost
    sides · c², c = 2 r sin(θ / (2 sides)); a finer polyline of the same polygon (every side cut
    in 7) gives the same."""
    r, theta = 1.3, 2.0
    phi = np.linspace(0.0, theta, sides + 1)
    vertices = r * np.c_[np.cos(phi), np.sin(phi)]
    t = np.linspace(0.0, 1.0, 8)[:-1]
    fine = np.vstack(
        [vertices[:-1, None] + t[None, :, None] * np.diff(vertices, axis=0)[:, None]]
    ).reshape(-1, 2)
    fine = np.vstack([fine, vertices[-1:]])
    chord = 2 * r * math.sin(theta / (2 * sides))
    for path in (vertices, fine):
        np.testing.assert_allclose(resample_arc_length(path, sides + 1), vertices, atol=1e-9)
        assert resampled_cost(path, sides + 1) == pytest.approx(sides * chord**2, rel=1e-9)
        assert path_length(path) == pytest.approx(sides * chord, rel=1e-9)


paths = st.integers(1, 8).flatmap(
    lambda k: arrays(float, (k, 3), elements=st.floats(-2.0, 2.0, allow_nan=False))
)


@settings(max_examples=200)
@given(path=paths, n=st.integers(2, 30), where=st.floats(0.0, 1.0))
def test_properties(path, n, where):
    """Endpoints kept; consecutive resampled points equally far apart along the path
    (each chord ≤ L/(n−1)); cost ≤ L²/(n−1); inserting a point on a segment changes nothing."""
    out = resample_arc_length(path, n)
    length = path_length(path)
    assert out.shape == (n, 3)
    np.testing.assert_array_equal(out[0], path[0])
    np.testing.assert_array_equal(out[-1], path[-1])
    chords = np.linalg.norm(np.diff(out, axis=0), axis=1)
    assert np.all(chords <= length / (n - 1) + 1e-9)
    assert resampled_cost(path, n) <= length**2 / (n - 1) + 1e-9
    if len(path) >= 2:
        split = path[0] + where * (path[1] - path[0])
        denser = np.vstack([path[:1], split, path[1:]])
        np.testing.assert_allclose(resample_arc_length(denser, n), out, atol=1e-9)
        assert path_length(denser) == pytest.approx(length, rel=1e-12, abs=1e-12)


def test_zero_length_path_and_bad_input():
    assert resampled_cost(np.zeros((3, 2)), 5) == 0.0
    np.testing.assert_array_equal(resample_arc_length(np.ones((1, 2)), 4), np.ones((4, 2)))
    with pytest.raises(InputError, match="path"):
        resampled_cost(np.zeros(3), 5)
    with pytest.raises(InputError, match="NaN"):
        path_length([[0.0, np.nan]])
    with pytest.raises(InputError, match="n"):
        resample_arc_length(np.zeros((2, 2)), 1)
