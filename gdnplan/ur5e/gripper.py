"""The 2F-85-like gripper on the UR5e's tool flange and the stick it holds: sizes and states.

Gripper (2F-85-like, attached to the tool flange): a 0.08 m long body (0.105 m across the
opening direction), two 0.05 m fingers, 0.01 m thick, on prismatic joints; the opening between
the finger faces is 0.085 m ``open``, 0 ``closed``, and the stick width when ``holding``.
The held stick is a box (``stick_width`` square section, ``stick_length`` long) along the
gripper axis, centred between the fingers, its near end ``GRASP_GAP`` in front of the palm:
it becomes one more robot polygon. Along the axis (not across it) is what a fetch through a
small entrance needs: the stick passes the entrance end first, and the fingers opening in the
plane straddle it from above and below.
"""

from __future__ import annotations

# gripper (m), in the gripper frame: z along the tool axis, y the opening direction
BODY_LENGTH, BODY_WIDTH, BODY_DEPTH = 0.08, 0.105, 0.07
FINGER_LENGTH, FINGER_THICKNESS, FINGER_DEPTH = 0.05, 0.01, 0.022
MAX_OPENING = 0.085
GRASP_GAP = 0.02  # stick end to palm (m)
TCP = BODY_LENGTH + FINGER_LENGTH / 2  # grasp centre on the tool axis, from the flange
GRIPPER_STATES = ("open", "closed", "holding")
