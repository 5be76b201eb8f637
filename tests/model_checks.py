"""Checks shared by the tests of learned distance models (imported by test modules)."""

from __future__ import annotations

import numpy as np


def assert_gradient_matches_central_differences(model, scene, qs: np.ndarray, h: float = 1e-7):
    """distance_and_grad's d equals distance's, and its gradient (B, dof) central differences
    of distance with step h (rad) to rtol 1e-4, atol 1e-8 (a piecewise smooth d̂: a larger
    step may cross a LeakyReLU kink)."""
    d, g = model.distance_and_grad(scene, qs)
    np.testing.assert_allclose(d, model.distance(scene, qs), atol=1e-12)
    for b, q in enumerate(qs):
        fd = [
            (model.distance(scene, q + e) - model.distance(scene, q - e))[0] / (2 * h)
            for e in np.eye(len(q)) * h
        ]
        np.testing.assert_allclose(g[b], fd, rtol=1e-4, atol=1e-8)


def assert_deterministic_and_continuous(model, scene, path: np.ndarray, step_bound: float):
    """d̂ along ``path`` (T, dof) is the same twice and moves < step_bound (m) per step."""
    d = model.distance(scene, path)
    np.testing.assert_array_equal(d, model.distance(scene, path))
    assert np.abs(np.diff(d)).max() < step_bound
