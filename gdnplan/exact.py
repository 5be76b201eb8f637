"""The exact-geometry protocol every scene kind satisfies: the planner, the seeds and the
certificate call these functions, never a planar or 3-D function directly.

=================== ============================ ==================================
function            planar ``Scene``             3-D ``Scene3D``
=================== ============================ ==================================
``exact_distance``  ``distance.signed_distance`` ``arm3d.signed_distance3d``
``certify``         ``ccd.certify_path``         ``arm3d.certify_path3d``
``motion_bound_of`` ``ccd.motion_bound``         ``arm3d.motion_bound3d``
``closest_pair``    the closest link             the closest pair (self pairs too)
``swept_radius_of`` 0 (prisms)                   largest sphere/capsule radius sum
=================== ============================ ==================================

Both scene kinds also share the attributes the planner reads: ``scene.robot`` with ``dof``,
``lower``, ``upper`` (rad), ``joint_names``, ``name``, ``check_q`` and a Pinocchio ``model``
(URDF velocity limits, :func:`gdnplan.timing.urdf_velocity`).

3-D contact-only self pairs (:mod:`gdnplan.arm3d.pairs`) must keep d ≥ 0, not the margin:
``exact_distance(scene, q, margin=M)`` and ``closest_pair(scene, q, margin=M)`` add M to their
distances, so a result ≥ M means every pair meets its requirement; without a margin they are
left out (the pairs a margin applies to). ``certify`` always proves both requirements.

Dispatch is by the scene's (or robot's) type with :func:`functools.singledispatch`: the scene
classes live in the core layer, below the coal geometry they would need as methods
(``tests/test_layers.py``), so the geometry registers itself for them here. Another scene kind
joins by registering its own implementations (``exact_distance.register(MyScene)``).
"""

from __future__ import annotations

import math
from functools import singledispatch

import numpy as np

from .arm3d.ccd3d import certify_path3d, motion_bound3d
from .arm3d.distance3d import checker3d
from .arm3d.robot3d import Robot3D
from .arm3d.scene3d import Scene3D
from .ccd import Certificate, certify_path, motion_bound
from .distance import closest, signed_distance
from .errors import InputError
from .robot import Robot
from .scene import Scene, check_scene


def _unknown(what, kind: str):
    if kind == "scene":
        check_scene(what, "any")  # raises: singledispatch found neither scene kind
    return InputError(f"{kind}: expected a planar Robot or a Robot3D, got {type(what).__name__}")


@singledispatch
def exact_distance(scene, q, per_link: bool = False, margin: float | None = None) -> np.ndarray:
    """Exact signed distance (m) of configurations q (B, dof) or (dof,): (B,), or (B, n_links)
    with ``per_link``; positive apart, minus the penetration depth in collision (3-D:
    self-collision included). ``margin`` (m), the clearance the result is compared with: 3-D
    contact-only self pairs count as d + margin (result ≥ margin ⟺ every pair meets its
    requirement); None leaves them out. A planar scene has none."""
    raise _unknown(scene, "scene")


@exact_distance.register
def _(scene: Scene, q, per_link: bool = False, margin: float | None = None) -> np.ndarray:
    return signed_distance(scene, q, per_link=per_link)


@exact_distance.register
def _(scene: Scene3D, q, per_link: bool = False, margin: float | None = None) -> np.ndarray:
    offset = math.inf if margin is None else margin
    return checker3d(scene).evaluate(q, per_link, contact_offset=offset).distance


@singledispatch
def certify(
    scene,
    q_path,
    margin: float = 0.0,
    tol: float = 1e-3,
    min_splits: int | None = None,
    stop_early: bool = False,
    max_checks: int | None = None,
) -> Certificate:
    """Prove that the piecewise-linear joint path q_path (K, dof) keeps the exact signed
    distance above ``margin`` (m) on the whole continuous path (conservative advancement);
    ``tol``: bisect until the reported lower bound is within tol of the smallest checked
    distance (``math.inf``: prove the margin only); ``min_splits``/``max_checks``: None for
    the scene kind's defaults (planar 10 / 200 000, 3-D 4 / 20 000)."""
    raise _unknown(scene, "scene")


def _given(**kwargs) -> dict:
    return {k: v for k, v in kwargs.items() if v is not None}


@certify.register
def _(scene: Scene, q_path, margin=0.0, tol=1e-3, min_splits=None, stop_early=False,
      max_checks=None) -> Certificate:  # fmt: skip
    extra = _given(min_splits=min_splits, max_checks=max_checks)
    return certify_path(scene, q_path, margin, tol=tol, stop_early=stop_early, **extra)


@certify.register
def _(scene: Scene3D, q_path, margin=0.0, tol=1e-3, min_splits=None, stop_early=False,
      max_checks=None) -> Certificate:  # fmt: skip
    extra = _given(min_splits=min_splits, max_checks=max_checks)
    return certify_path3d(scene, q_path, margin, tol=tol, stop_early=stop_early, **extra)


@singledispatch
def motion_bound_of(robot, qa, qb) -> np.ndarray:
    """(B,) bound (m) on how far any robot point moves (3-D: how much any pair's distance
    changes) along the straight joint segments qa → qb (B, dof)."""
    raise _unknown(robot, "robot")


@motion_bound_of.register
def _(robot: Robot, qa, qb) -> np.ndarray:
    return motion_bound(robot, qa, qb)


@motion_bound_of.register
def _(robot: Robot3D, qa, qb) -> np.ndarray:
    return motion_bound3d(robot, qa, qb)


@singledispatch
def swept_radius_of(scene) -> float:
    """The largest sum of swept-sphere radii of a pair of the scene (m): what
    :func:`gdnplan.ccd.proven_distance` adds to coal's relative slack (0 for planar prisms;
    3-D: sphere and capsule radii, :attr:`gdnplan.arm3d.narrow3d.PairTable.swept_max`)."""
    raise _unknown(scene, "scene")


@swept_radius_of.register
def _(scene: Scene) -> float:
    return 0.0


@swept_radius_of.register
def _(scene: Scene3D) -> float:
    return checker3d(scene).swept_max


@singledispatch
def closest_pair(scene, q, margin: float | None = None) -> str:
    """What is closest at one configuration q (dof,), for messages: ``"link 'a' and obstacle
    3"`` (planar) or ``"forearm_link/... and box4"`` (3-D, self pairs name both links);
    ``margin`` as in :func:`exact_distance`."""
    raise _unknown(scene, "scene")


@closest_pair.register
def _(scene: Scene, q, margin: float | None = None) -> str:
    w = closest(scene, scene.robot.check_q(q))
    return f"link {int(w.link[0])} and an obstacle"


@closest_pair.register
def _(scene: Scene3D, q, margin: float | None = None) -> str:
    checker = checker3d(scene)
    offset = math.inf if margin is None else margin
    pair = int(checker.evaluate(q, contact_offset=offset).pair[0])
    if pair < 0:
        return "no pair"
    a, b = checker.pair_names()[pair]
    if checker.contact_only[pair]:
        return f"{a} and {b} (self-collision, contact-only: must keep d ≥ 0)"
    return f"{a} and {b}" + (" (self-collision)" if checker.is_self[pair] else "")


__all__ = ["certify", "closest_pair", "exact_distance", "motion_bound_of", "swept_radius_of"]
