"""3-D browser view (meshcat) of a plan: the full robot and the scene's obstacles extruded.

The planner works in the robot's plane; this view shows what that means for the real arm. The
robot is its full Pinocchio model (all joints, the collision geometry of its URDF) with the
planning joints following the plan and every other joint at its locked value. The locked
values are read back from the robot's reduced model, which keeps each locked joint as a fixed
frame placed at its value: no per-robot table. Obstacles are their convex parts (what coal
checks), each extruded along the plane normal by ``depth`` and centred on the tool's
out-of-plane offset, so the stick lies between the fingers in 3-D too. The 2-D check is
valid for any depth: two prisms cannot touch when their projections do not.

A fetch stick is the box it is: ``stick_width`` deep (its square section), lying on its shelf
while it is an obstacle, and carried by the gripper (its near end ``GRASP_GAP`` in front of the
palm, as :mod:`gdnplan.ur5e` attaches it) while the robot holds it.

3-D plans (:class:`~gdnplan.arm3d.Scene3D`) need no extrusion: :mod:`~gdnplan.viz3d.meshes`
turns the coal shapes of the arm and the obstacles into triangle meshes, which
:mod:`~gdnplan.viz3d.animate` renders into a GIF with matplotlib (headless, no meshcat) and
:mod:`~gdnplan.viz3d.viewer3d` sends to meshcat.

Needs ``pip install meshcat`` (the ``viz3d`` extra) for the browser view; :func:`scene_objects`,
:func:`full_robot` and :func:`frame_poses` are pure and work without it.

Modules: :mod:`~gdnplan.viz3d.objects` (obstacles as prisms), :mod:`~gdnplan.viz3d.model`
(the full robot and the held stick), :mod:`~gdnplan.viz3d.frames` (animation frames) and
:mod:`~gdnplan.viz3d.viewer` (meshcat); for 3-D plans :mod:`~gdnplan.viz3d.meshes`,
:mod:`~gdnplan.viz3d.animate` (the GIF) and :mod:`~gdnplan.viz3d.viewer3d` (meshcat); every
public name is re-exported here.
"""

from __future__ import annotations

from .animate import animate_paths3d
from .frames import Frame, frame_poses
from .meshes import obstacle_triangles, robot_triangles, shape_mesh, tool_positions
from .model import FullRobot, full_robot, held_stick
from .objects import COLORS, DEPTH, OBSTACLE_COLOR, Prism, scene_objects, tool_offset
from .viewer import (
    INSTALL_HINT,
    ROBOT_COLOR,
    camera_placement,
    require_meshcat,
    send_plan,
    view_plan,
)
from .viewer3d import Mesh3D, camera3d, frames3d, scene3d_meshes, send_plan3d

__all__ = [
    "COLORS",
    "DEPTH",
    "INSTALL_HINT",
    "OBSTACLE_COLOR",
    "ROBOT_COLOR",
    "Frame",
    "FullRobot",
    "Mesh3D",
    "Prism",
    "animate_paths3d",
    "camera3d",
    "camera_placement",
    "frame_poses",
    "frames3d",
    "full_robot",
    "held_stick",
    "obstacle_triangles",
    "require_meshcat",
    "robot_triangles",
    "scene3d_meshes",
    "scene_objects",
    "send_plan",
    "send_plan3d",
    "shape_mesh",
    "tool_offset",
    "tool_positions",
    "view_plan",
]
