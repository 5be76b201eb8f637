"""The certificate of a path leaving a resting contact (gdnplan.ccd_contact), against an
independent truth: the arm's tip resting on a wide floor box, whose penetration depth is the
tip's vertical intrusion below the box top (forward kinematics of the link polygons, no coal)."""

import itertools

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

import gdnplan as gp
from gdnplan.ccd_contact import CONTACT_ALLOWANCE, certify_from_contact
from gdnplan.errors import InputError
from gdnplan.scene import Scene

ROBOT = gp.make_scene("a").robot  # planar2: two links from the origin
Q_REST = np.array([-1.2, 0.3])  # the tip points down, its lowest vertex at y ≈ −1.05 m


def floor_scene(q_rest: np.ndarray) -> tuple[Scene, float]:
    """A 0.6 m wide box whose top touches the tip's lowest vertex at ``q_rest``; its top y."""
    tip = ROBOT.link_polygons(q_rest)[-1]
    low = tip[np.argmin(tip[:, 1])]
    x, top = low
    box = np.array([[x - 0.3, top - 0.5], [x + 0.3, top - 0.5], [x + 0.3, top], [x - 0.3, top]])
    return Scene(ROBOT, (box,)), float(top)


def deepest(path: np.ndarray, top: float, samples: int = 4001) -> float:
    """Largest penetration depth (m) along the straight segments of ``path`` (the tip's
    vertical intrusion below ``top``; 0 when above)."""
    s = np.linspace(0.0, 1.0, samples)[:, None]
    worst = 0.0
    for qa, qb in itertools.pairwise(path):
        for q in qa + s * (qb - qa):
            worst = max(worst, top - float(ROBOT.link_polygons(q)[-1][:, 1].min()))
    return worst


def test_a_lift_off_the_floor_is_proven_and_a_push_into_it_is_not():
    scene, top = floor_scene(Q_REST)
    assert abs(gp.signed_distance(scene, Q_REST)[0]) < 1e-9  # resting contact
    up = np.array([Q_REST, Q_REST + np.array([0.02, 0.0])])  # the shoulder turns the tip up and out
    assert deepest(up, top) == pytest.approx(0.0, abs=1e-12)
    cert = certify_from_contact(scene, up)
    assert cert.ok and cert.lower_bound > -CONTACT_ALLOWANCE and cert.n_checks < 200
    down = np.array([Q_REST, Q_REST - np.array([0.02, 0.0])])
    assert deepest(down, top) > 1e-3
    assert not certify_from_contact(scene, down).ok
    assert certify_from_contact(scene, Q_REST[None]).ok  # the contact itself: within 10 µm


@settings(max_examples=40, deadline=None)
@given(
    rest=st.tuples(st.floats(-1.6, -0.8), st.floats(-0.6, 0.6)),
    step=st.tuples(st.floats(-0.03, 0.03), st.floats(-0.03, 0.03)),
    bend=st.tuples(st.floats(-0.02, 0.02), st.floats(-0.02, 0.02)),
)
@example(rest=(-1.2, 0.3), step=(0.02, 0.0), bend=(0.0, 0.0))  # proven: straight up
@example(rest=(-1.2, 0.3), step=(1e-4, -3e-4), bend=(0.0, 0.0))  # grazes: tip rolls over
@example(rest=(-1.2, 0.3), step=(0.02, 0.0), bend=(-0.019, 0.0))  # out, then back in
def test_a_certified_path_never_penetrates_by_the_allowance(rest, step, bend):
    q0 = np.array(rest)
    scene, top = floor_scene(q0)
    q1 = q0 + np.array(step)
    path = np.array([q0, q1, q1 + np.array(bend)])
    cert = certify_from_contact(scene, path)
    if cert.ok:
        assert deepest(path, top) < CONTACT_ALLOWANCE
        assert cert.lower_bound > -CONTACT_ALLOWANCE


@pytest.mark.parametrize("allowance", [0.0, -1e-5, 2e-3, float("nan"), True, "1e-5"])
def test_the_allowance_is_a_small_positive_depth(allowance):
    scene, _ = floor_scene(Q_REST)
    with pytest.raises(InputError, match=r"^allowance: "):
        certify_from_contact(scene, Q_REST[None], allowance=allowance)


def test_bad_paths_are_refused():
    scene, _ = floor_scene(Q_REST)
    with pytest.raises(InputError, match=r"q_path"):
        certify_from_contact(scene, np.zeros((0, 2)))
    with pytest.raises(InputError, match=r"q_path"):
        certify_from_contact(scene, np.full((2, 2), np.nan))
