"""A held object rigidly attached to a 3-D robot's tool frame: one more link shape of the arm.

:func:`hold` returns a copy of a :class:`~gdnplan.arm3d.robot3d.Robot3D` whose last body (the
one the tool frame f hangs from) carries one more shape, the held object, at the placement

    ʲM_obj = ʲM_f · ᶠM_obj                                        (4, 4), m

with ʲM_f the tool frame's fixed placement in its joint frame and ᶠM_obj the object's in the tool
frame. Distances, gradients (:mod:`gdnplan.arm3d.distance3d`) and the continuous certificate
(:mod:`gdnplan.arm3d.ccd3d`) treat it like any link shape: obstacle pairs, and self-collision
pairs with every link except those on its own body — the gripper that holds it (its body, its
locked fingers, the flange's wrist link), whose distance to it never changes (the fingers touch
it by design). Unlike link pairs, the held object *is* checked against the adjacent link (the
UR5e's wrist 2): it reaches far from the joint they share.

:func:`stick` is the fetch's held stick: a box of square section ``width`` and ``length`` along
the tool axis z, centred between the fingers, its near end ``gap`` in front of the palm.
"""

from __future__ import annotations

import numpy as np

from ..errors import InputError
from ..limits import shown
from ..ur5e.gripper import FINGER_LENGTH, GRASP_GAP
from .ik3d import tool_frame
from .robot3d import LinkShape, Robot3D
from .scene3d import check_robot3d
from .shapes import as_pose, bounding_sphere, box, check_shape

HELD_LINK = "held_object"  # the link name of the held object's shape


def stick(length: float, width: float, gap: float = GRASP_GAP):
    """The fetch stick held by the UR5e's gripper: (coal box, (4, 4) placement in the tcp frame).

    The tcp sits halfway along the fingers, so the palm is at z = −FINGER_LENGTH/2 and the
    stick spans z ∈ [gap − FINGER_LENGTH/2, gap − FINGER_LENGTH/2 + length] (m).
    """
    shape = box((width, width, length), "stick")
    placement = np.eye(4)
    placement[2, 3] = gap - FINGER_LENGTH / 2 + length / 2
    return shape, placement


def hold(
    robot: Robot3D,
    shape,
    placement=None,
    name: str = "stick",
    frame: str | None = None,
) -> Robot3D:
    """A copy of ``robot`` holding ``shape`` (a coal shape from :mod:`gdnplan.arm3d.shapes`)
    at ``placement`` (4, 4) in ``frame`` (default: the tool frame; None placement: identity).

    The copy's ``info`` records ``held`` (the object's name), ``tool_frame`` and
    ``held_placement`` (the (4, 4) placement in that frame). InputError
    when the robot already holds an object or the frame is unknown.
    """
    check_robot3d(robot)
    if not isinstance(name, str):
        raise InputError(f"name: expected the held object's name (a string), got {shown(name)}")
    if HELD_LINK in robot.links:
        raise InputError(f"hold: {robot.name} already holds {robot.info.get('held')!r}")
    frame = tool_frame(robot) if frame is None else frame
    model = robot.model
    if not isinstance(frame, str) or not model.existFrame(frame):
        raise InputError(f"frame: {frame!r} is not a frame of {robot.name}")
    try:
        tf = np.eye(4) if placement is None else np.asarray(placement)
    except ValueError as e:  # ragged rows
        raise InputError(f"placement: expected a (4, 4) transform, got {shown(placement)}") from e
    if tf.dtype.kind not in "iuf":  # a string, complex numbers (cast silently), objects
        raise InputError(f"placement: expected a (4, 4) transform, got {shown(placement)}")
    tf = tf.astype(float)
    if tf.shape != (4, 4) or not np.all(np.isfinite(tf)) or not np.allclose(tf[3], [0, 0, 0, 1]):
        raise InputError("placement: expected a (4, 4) homogeneous transform of finite numbers")
    as_pose(tf[:3, 3], tf[:3, :3], "placement")  # validates the rotation
    fr = model.frames[model.getFrameId(frame)]
    body = int(fr.parentJoint)
    center, radius = bounding_sphere(check_shape(shape, "held"))
    held = LinkShape(name, HELD_LINK, body, shape, fr.placement.homogeneous @ tf, center, radius)
    shapes = (*robot.shapes, held)
    k = len(shapes) - 1
    new_pairs = [(i, k) for i, s in enumerate(robot.shapes) if s.body != body]
    pairs = np.vstack([robot.self_pairs, np.array(new_pairs, dtype=int).reshape(-1, 2)])
    disabled = dict(robot.disabled)
    for link in dict.fromkeys(s.link for s in robot.shapes if s.body == body):
        disabled[frozenset((link, HELD_LINK))] = "same body: the gripper holds it"
    info = {**robot.info, "held": name, "tool_frame": frame, "held_placement": tf.copy()}
    return Robot3D(robot.name, model, shapes, pairs, disabled, info, robot.contact_only)


__all__ = ["HELD_LINK", "hold", "stick"]
