"""Forward kinematics of a batch of configurations in numpy: every shape's world placement for
B configurations at once (the distance's broad phase and the certificate evaluate hundreds of
configurations per call, and Pinocchio's per-configuration Python round trip dominated them).

For joint i with parent λ(i), fixed placement P_i (in the parent's joint frame) and motion
M_i(q_i),

    ᵒM_i = ᵒM_{λ(i)} · P_i · M_i(q_i),      M_i = [R(a_i, q_i) 0; 0 1] (revolute, unit axis a_i)
                                              M_i = [I a_i q_i; 0 1]     (prismatic)

with R(a, θ) = I + sin θ [a]× + (1 − cos θ) [a]×² (Rodrigues). Revolute and prismatic joints
about any axis are supported (Pinocchio's RX/RY/RZ/PX/PY/PZ and the unaligned kinds); a model
with another joint kind falls back to Pinocchio per configuration. A test compares both with
Pinocchio's ``forwardKinematics``.
"""

from __future__ import annotations

import weakref

import numpy as np

from .robot3d import Robot3D

_AXES = {"X": (1.0, 0.0, 0.0), "Y": (0.0, 1.0, 0.0), "Z": (0.0, 0.0, 1.0)}
_STATIC: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()  # robot -> its joint table


def _joint_table(robot: Robot3D) -> list[tuple[int, np.ndarray, str, np.ndarray, int]] | None:
    """(parent, P_i (4, 4), "R"/"P", axis (3,), q index) per joint, None for other kinds."""
    model, rows = robot.model, []
    for i in range(1, model.njoints):
        joint = model.joints[i]
        name = joint.shortname().removeprefix("JointModel")
        if name in ("RevoluteUnaligned", "PrismaticUnaligned"):
            kind, axis = name[0], np.asarray(joint.extract().axis, float)
        elif len(name) == 2 and name[0] in "RP" and name[1] in _AXES:
            kind, axis = name[0], np.array(_AXES[name[1]])
        else:
            return None
        rows.append(
            (int(model.parents[i]), model.jointPlacements[i].homogeneous, kind, axis, joint.idx_q)
        )
    return rows


def _table(robot: Robot3D):
    if robot not in _STATIC:
        local = np.array([s.placement for s in robot.shapes]).reshape(-1, 4, 4)
        _STATIC[robot] = (_joint_table(robot), local)
    return _STATIC[robot]


def _motion(kind: str, axis: np.ndarray, theta: np.ndarray) -> np.ndarray:
    """(B, 4, 4) joint motions M(q) of one joint for B values (rad or m)."""
    out = np.tile(np.eye(4), (len(theta), 1, 1))
    if kind == "P":
        out[:, :3, 3] = theta[:, None] * axis
        return out
    k = np.array([[0.0, -axis[2], axis[1]], [axis[2], 0.0, -axis[0]], [-axis[1], axis[0], 0.0]])
    s, c = np.sin(theta)[:, None, None], np.cos(theta)[:, None, None]
    out[:, :3, :3] += s * k + (1.0 - c) * (k @ k)
    return out


def body_placements_batch(robot: Robot3D, q: np.ndarray) -> np.ndarray:
    """(B, njoints, 4, 4) world placements of every body's joint frame at q (B, dof)."""
    q = robot.check_q(q)
    table, _ = _table(robot)
    if table is None:  # a joint kind numpy does not model: Pinocchio per configuration
        return np.stack([robot.body_placements(qi) for qi in q])
    out = np.empty((len(q), robot.model.njoints, 4, 4))
    out[:, 0] = np.eye(4)
    for i, (parent, fixed, kind, axis, iq) in enumerate(table, start=1):
        out[:, i] = out[:, parent] @ fixed @ _motion(kind, axis, q[:, iq])
    return out


def shape_placements_batch(robot: Robot3D, q: np.ndarray) -> np.ndarray:
    """(B, S, 4, 4) world placements of every link shape at q (B, dof)."""
    bodies = body_placements_batch(robot, q)
    _, local = _table(robot)
    return bodies[:, robot.shape_body] @ local


__all__ = ["body_placements_batch", "shape_placements_batch"]
