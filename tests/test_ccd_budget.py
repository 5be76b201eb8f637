"""The certificates' check budget: never exceeded, checked before the first coal call, and a
certificate is ``ok`` only with an empty reason (planar, 3-D and the cubic-curve one)."""

from __future__ import annotations

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
