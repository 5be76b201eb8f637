"""UR5e and UR5 arms in their vertical plane, a 2F-85-like gripper, and the fetch scene.

One module per concern; every name is re-exported here (``from gdnplan.ur5e import …``):

- :mod:`~gdnplan.ur5e.kinematics`: DH parameters, joint names, the planning plane and limits;
- :mod:`~gdnplan.ur5e.gripper`: gripper and held-stick sizes, the gripper states;
- :mod:`~gdnplan.ur5e.urdf`: the UR5e + gripper URDF written from the DH parameters;
- :mod:`~gdnplan.ur5e.arms`: the registered ``ur5e`` and ``ur5`` robots;
- :mod:`~gdnplan.ur5e.ik`: the planar tcp pose and its exact inverse kinematics;
- :mod:`~gdnplan.ur5e.layout`: fetch layouts (storage box, entrance, stick, tcp targets);
- :mod:`~gdnplan.ur5e.scene`: the registered ``fetch`` scene (needs coal distances);
- :mod:`~gdnplan.ur5e.plot`: a PNG of a fetch scene.

The robot modules are core robot modelling; the fetch scene and its plot need coal's signed
distance, so this package (its ``__init__``) sits in the "exact geometry" layer.
``solve_ik`` is the deprecated name of :func:`analytic_ik`.
"""

from __future__ import annotations

import warnings

from .arms import POLYGON_GROUPS, UR5_GROUPS, ur5, ur5e
from .gripper import (
    BODY_DEPTH,
    BODY_LENGTH,
    BODY_WIDTH,
    FINGER_DEPTH,
    FINGER_LENGTH,
    FINGER_THICKNESS,
    GRASP_GAP,
    GRIPPER_STATES,
    MAX_OPENING,
    TCP,
)
from .ik import analytic_ik, tcp_pose
from .kinematics import (
    DH,
    JOINTS,
    LINKS,
    LOCKED,
    PI,
    PLANE_AXES,
    PLANNING_JOINTS,
    PLANNING_LIMITS,
    UR5_DH,
    UR5E_DH,
)
from .layout import CANONICAL_FETCH, LIFT, TABLE_V, FetchLayout, random_fetch_layout
from .plot import plot_fetch
from .scene import MAX_FETCH_TRIES, MIN_CLEARANCE, fetch_configurations, fetch_scene
from .urdf import ur5e_urdf

_DEPRECATED = {"solve_ik": ("analytic_ik", analytic_ik)}  # old name -> (new name, object)


def __getattr__(name: str) -> object:
    """Deprecated names: warn (DeprecationWarning naming the new one), then return it."""
    if name in _DEPRECATED:
        new, value = _DEPRECATED[name]
        warnings.warn(
            f"gdnplan.ur5e.{name} is deprecated; use gdnplan.ur5e.{new} (the exact planar "
            "IK of the tcp pose; the planner's numeric goal IK is gdnplan.trajopt.numeric_ik)",
            DeprecationWarning,
            stacklevel=2,
        )
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


__all__ = [
    "BODY_DEPTH",
    "BODY_LENGTH",
    "BODY_WIDTH",
    "CANONICAL_FETCH",
    "DH",
    "FINGER_DEPTH",
    "FINGER_LENGTH",
    "FINGER_THICKNESS",
    "GRASP_GAP",
    "GRIPPER_STATES",
    "JOINTS",
    "LIFT",
    "LINKS",
    "LOCKED",
    "MAX_FETCH_TRIES",
    "MAX_OPENING",
    "MIN_CLEARANCE",
    "PI",
    "PLANE_AXES",
    "PLANNING_JOINTS",
    "PLANNING_LIMITS",
    "POLYGON_GROUPS",
    "TABLE_V",
    "TCP",
    "UR5E_DH",
    "UR5_DH",
    "UR5_GROUPS",
    "FetchLayout",
    "analytic_ik",
    "fetch_configurations",
    "fetch_scene",
    "plot_fetch",
    "random_fetch_layout",
    "tcp_pose",
    "ur5",
    "ur5e",
    "ur5e_urdf",
]
