"""The certificates' check budget: never exceeded, checked before the first coal call, and a
certificate is ``ok`` only with an empty reason (planar, 3-D and the cubic-curve one)."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.interpolate import PchipInterpolator

import gdnplan as gp
from gdnplan import arm3d, ccd
from gdnplan.ccd_curve import certify_curve

SCENE = gp.make_scene("b", seed=0)
SCENE3D = arm3d.random_boxes(arm3d.load_robot3d("ur5e"), 3, seed=0)
HOME3D = np.array([0.0, -1.57, 1.57, -1.57, -1.57, 0.0])


def assert_honest(cert: ccd.Certificate, max_checks: int, needed: int) -> None:
    """The certificate's invariants (module docstring of gdnplan.ccd)."""
    assert cert.n_checks <= max_checks
    assert cert.ok == (cert.reason == "")
    if cert.ok:
        assert cert.lower_bound > -math.inf and not cert.bad_segments
    else:
        assert cert.lower_bound == -math.inf and cert.bad_segments
    if needed > max_checks:  # refused up front: no coal call at all
        assert not cert.ok and cert.n_checks == 0 and "cannot hold" in cert.reason


@settings(max_examples=60, deadline=None)
@given(
    splits=st.integers(1, ccd.MAX_SPLITS),
    max_checks=st.integers(1, 3000),
    waypoints=st.integers(1, 4),
    seed=st.integers(0, 1000),
)
def test_planar_budget_is_never_exceeded(splits, max_checks, waypoints, seed):
    path = SCENE.robot.sample(waypoints, seed=seed) * 0.3
    cert = gp.certify_path(SCENE, path, min_splits=splits, max_checks=max_checks)
    needed = (1 if waypoints == 1 else (waypoints - 1) * splits) + 1
    assert_honest(cert, max_checks, needed)


@settings(max_examples=15, deadline=None)
@given(splits=st.integers(1, ccd.MAX_SPLITS), max_checks=st.integers(1, 200))
def test_3d_budget_is_never_exceeded(splits, max_checks):
    path = np.stack([HOME3D, HOME3D + 0.2, HOME3D - 0.1])
    cert = arm3d.certify_path3d(SCENE3D, path, min_splits=splits, max_checks=max_checks)
    assert_honest(cert, max_checks, 2 * splits + 1)


def test_the_audits_case_is_refused():
    path = [[0, 0], [0.1, 0]]
    with pytest.raises(
        gp.InputError, match=r"^min_splits: expected an integer in \[1, 10000\], got 1000000"
    ):
        gp.certify_path(SCENE, path, min_splits=10**6, max_checks=10)
    with pytest.raises(gp.InputError, match=r"^min_splits: expected an integer in \[1, 10000\]"):
        arm3d.certify_path3d(SCENE3D, np.stack([HOME3D, HOME3D]), min_splits=10**6)
    cert = gp.certify_path(SCENE, path, min_splits=10**4, max_checks=10)
    assert not cert.ok and cert.n_checks == 0 and cert.bad_segments == (0,)
    assert "10001 checks" in cert.reason and cert.min_distance == math.inf


def test_a_budget_that_holds_the_initial_pieces_still_proves():
    path = [[0, 0], [0.1, 0]]
    cert = gp.certify_path(SCENE, path, min_splits=10, max_checks=11, tol=math.inf)
    assert cert.ok and cert.reason == "" and cert.n_checks == 11


@settings(max_examples=30, deadline=None)
@given(splits=st.integers(1, ccd.MAX_SPLITS), max_checks=st.integers(1, 2000))
def test_curve_budget_is_never_exceeded(splits, max_checks):
    curve = PchipInterpolator([0.0, 0.5, 1.0], [[0.0, 0.0], [0.2, 0.1], [0.3, -0.1]])
    cert = certify_curve(SCENE, curve, splits=splits, max_checks=max_checks)
    assert cert.n_checks <= max_checks
    if 2 * splits + 1 > max_checks:
        assert not cert.ok and cert.n_checks == 0
    assert cert.ok == (cert.lower_bound > -math.inf)


def test_a_path_proven_at_the_margin_is_not_failed_for_want_of_a_tight_bound():
    """The UR5e path is proven above 2 cm with 126 checks (tol = inf); with tol = 1e-3 the
    bisection went on tightening the bound and failed at 1000 ("the check budget ran out"),
    as the planner's final certificate failed a 40-joint arm's straight line proven free."""
    path = np.stack([HOME3D, HOME3D + 0.2, HOME3D - 0.1])
    margin_only = arm3d.certify_path3d(SCENE3D, path, margin=0.02, tol=math.inf)
    assert margin_only.ok and margin_only.n_checks < 200
    for max_checks in (200, 1000):
        cert = arm3d.certify_path3d(SCENE3D, path, 0.02, tol=1e-3, max_checks=max_checks)
        assert cert.ok and cert.reason == "" and cert.n_checks <= max_checks
        assert 0.02 < cert.lower_bound <= cert.min_distance
    tight = arm3d.certify_path3d(SCENE3D, path, 0.02, tol=1e-3, max_checks=20_000)
    assert tight.ok and tight.min_distance - tight.lower_bound <= 1e-3  # budget enough: tight


@settings(max_examples=25, deadline=None)
@given(
    max_checks=st.integers(1, 1500),
    tol=st.sampled_from([1e-6, 1e-3, math.inf]),
    scale=st.floats(0.05, 0.6),
    seed=st.integers(0, 1000),
)
def test_a_certificate_cut_short_by_its_budget_is_still_sound(max_checks, tol, scale, seed):
    """Whatever the budget: ok only with every sampled configuration's exact distance above
    the proven lower bound, and that bound above the margin."""
    from gdnplan.exact import exact_distance

    rng = np.random.default_rng(seed)
    path = HOME3D + scale * rng.uniform(-1, 1, (3, 6))
    cert = arm3d.certify_path3d(SCENE3D, path, margin=0.01, tol=tol, max_checks=max_checks)
    assert_honest(cert, max_checks, 2 * 4 + 1)
    if cert.ok:
        s = np.linspace(0, 1, 40)[:, None]
        dense = np.concatenate([a + s * (b - a) for a, b in itertools.pairwise(path)])
        sampled = float(np.min(exact_distance(SCENE3D, dense, margin=0.01)))
        assert 0.01 < cert.lower_bound <= sampled


def test_a_curve_proven_at_the_margin_is_not_refused_for_want_of_a_tight_bound():
    """The cubic through the same waypoints is proven above 2 cm with 119 checks (tol huge);
    with tol = 1e-3 it was refused at 200, 400 and 1000 checks, so time_path fell back to
    'stop' for a curve that is certified."""
    from gdnplan.exact import exact_distance

    curve = PchipInterpolator([0.0, 1.0, 2.0], np.stack([HOME3D, HOME3D + 0.2, HOME3D - 0.1]))
    dense = curve(np.linspace(0.0, 2.0, 400))
    sampled = float(np.min(exact_distance(SCENE3D, dense, margin=0.02)))
    for max_checks in (200, 400, 1000):
        cert = certify_curve(SCENE3D, curve, 0.02, tol=1e-3, max_checks=max_checks)
        assert cert.ok and cert.n_checks <= max_checks
        assert 0.02 < cert.lower_bound <= sampled
