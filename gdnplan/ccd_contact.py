"""The certificate of a path that leaves a resting contact (planar and 3-D scenes).

A held part resting on its shelf (the fetch's stick at the grasp) touches an obstacle: its
exact signed distance is 0 there, so no clearance ≥ 0 can be proven at the start of the lift
that takes it off. What can be proven is that the path never *penetrates*: by more than an
``allowance`` a > 0, i.e.

    d(q(s)) > −a     for every s on the continuous piecewise-linear path,

with the bisection proof of :func:`gdnplan.ccd.certify_path` (and
:func:`gdnplan.arm3d.certify_path3d`) run at the margin −a. A piece [q_a, q_b] is proven when

    (d̲(q_a) + d̲(q_b) − δ(q_a, q_b)) / 2 > −a,

d̲ coal's distance minus its error allowance (:func:`gdnplan.ccd.proven_distance`, about
2 µm at contact; in 3-D, a pair coal finds closer than 0.1 mm, overlapping ones above all,
gets the translated bound of :mod:`gdnplan.arm3d.depth3d`, since coal's EPA depth on curved
shapes stops short by more than that slack) and δ the largest motion of any robot point
between the ends. At the contact d̲ ≈ −2 µm, so the first proven piece is short
(δ < 2a − 4 µm), and as the path leaves the contact at a rate v ≤ δ per unit of s, d̲ grows
and the pieces grow geometrically: a lift of a few millimetres is proven with tens of coal
calls. A path that moves *into* the contact (d decreasing) is not proven (it is not a lift).
Contact-only self pairs of a 3-D robot must still stay apart (d > 0), as in
:func:`gdnplan.arm3d.certify_path3d`.

``allowance`` must exceed coal's error at contact for a proof to exist; the default
:data:`CONTACT_ALLOWANCE` (10 µm) is five times it and far below any mechanical tolerance.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from .arm3d.depth3d import contact_distances3d
from .ccd import MAX_CHECKS, MAX_SPLITS, Certificate, certify_by_bisection, check_path
from .errors import InputError
from .exact import exact_distance, motion_bound_of, swept_radius_of
from .limits import check_int, check_number
from .scene import Scene, check_scene

if TYPE_CHECKING:
    from .arm3d.scene3d import Scene3D

CONTACT_ALLOWANCE = 1e-5  # m: the proven bound on penetration along a path leaving contact
MAX_ALLOWANCE = 1e-3  # m: a larger "allowance" is a collision, not a contact
CONTACT_SPLITS = 10  # pieces each waypoint segment starts with
CONTACT_MAX_CHECKS = 20_000  # coal evaluations allowed


def certify_from_contact(
    scene: Scene | Scene3D,
    q_path: np.ndarray,
    allowance: float = CONTACT_ALLOWANCE,
    min_splits: int = CONTACT_SPLITS,
    max_checks: int = CONTACT_MAX_CHECKS,
) -> Certificate:
    """Prove that the piecewise-linear path q_path (K, dof) (rad) keeps the exact signed
    distance > −``allowance`` (m) (module docstring); K = 1 checks one configuration.

    Args:
        scene: a planar ``Scene`` or a ``Scene3D`` (contact-only self pairs: d > 0).
        q_path: (K, dof) waypoints, K ≥ 1.
        allowance: penetration depth proven not to be exceeded (m), in (0, MAX_ALLOWANCE].
        min_splits: pieces each waypoint segment starts with.
        max_checks: coal evaluations allowed; running out is a failure.

    Returns:
        a :class:`gdnplan.ccd.Certificate`: ``ok`` with a proof on every piece, then
        ``lower_bound`` > −allowance; ``min_distance`` the smallest distance checked (coal's,
        or in 3-D the translated bound of a pair closer than 0.1 mm plus coal's slack,
        :func:`gdnplan.arm3d.depth3d.contact_distances3d`, when that is smaller).
    """
    check_scene(scene, "any")
    allowance = check_number(allowance, "allowance", strict=True)
    if allowance > MAX_ALLOWANCE:
        raise InputError(
            f"allowance: expected at most {MAX_ALLOWANCE} m of penetration (a contact), got "
            f"{allowance}; prove a clearance with certify_path instead"
        )
    check_int(min_splits, "min_splits", 1, MAX_SPLITS)
    check_int(max_checks, "max_checks", 1, MAX_CHECKS)
    robot = scene.robot
    q_path = check_path(robot, q_path)
    return certify_by_bisection(
        q_path,
        _distance(scene, -allowance),
        lambda qa, qb: motion_bound_of(robot, qa, qb),
        -allowance,
        math.inf,
        min_splits,
        False,
        max_checks,
        swept_radius_of(scene),
    )


def _distance(scene: Scene | Scene3D, margin: float):
    """q (B, dof) → (B,) distances whose ``proven_distance`` is a proven lower bound also where
    pairs overlap: a 3-D scene's overlapping pairs get the translated bound of
    :mod:`gdnplan.arm3d.depth3d` (coal's EPA depth on curved shapes stops short by more than
    its slack); planar prisms are polytopes, whose EPA depth (tolerance 1e-9) is exact."""
    if isinstance(scene, Scene):
        return lambda q: exact_distance(scene, q, margin=margin)
    return lambda q: contact_distances3d(scene, q, margin)


def contact_detail(cert: Certificate, allowance: float = CONTACT_ALLOWANCE) -> str:
    """What a :func:`certify_from_contact` certificate at ``allowance`` (m) proved, in words."""
    if not cert.ok:
        return f"not proven within {1e6 * allowance:.0f} µm of contact ({cert.reason})"
    return (
        f"proven never to penetrate by {1e6 * allowance:.0f} µm (d ≥ {cert.lower_bound:.2g} m, "
        f"{cert.n_checks} coal checks)"
    )


__all__ = ["CONTACT_ALLOWANCE", "MAX_ALLOWANCE", "certify_from_contact", "contact_detail"]
