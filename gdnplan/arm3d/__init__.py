"""3-D arms: robots from URDF through Pinocchio, posed convex obstacles, exact coal signed
distance with self-collision and its gradient.

* :mod:`gdnplan.arm3d.shapes`: validated coal shapes (primitives, hulls, meshes);
  :mod:`gdnplan.arm3d.shape_numbers`: their coordinate, size and point checks;
  :mod:`gdnplan.arm3d.poses`: poses (position, quaternion or rotation matrix).
* :mod:`gdnplan.arm3d.robot3d`: :class:`Robot3D` from any URDF (its link shapes:
  :mod:`gdnplan.arm3d.link_shape`); :mod:`gdnplan.arm3d.builtin`:
  the UR5e, Panda and UR5; :mod:`gdnplan.arm3d.pairs`: self-collision pairs (SRDF).
* :mod:`gdnplan.arm3d.scene3d`: obstacles and :class:`Scene3D`.
* :mod:`gdnplan.arm3d.distance3d`: signed distance and its minimising pairs (broad phase);
  :mod:`gdnplan.arm3d.narrow3d`: the pair table and coal's narrow phase;
  :mod:`gdnplan.arm3d.gradient3d`: the exact gradient.
* :mod:`gdnplan.arm3d.ccd3d`: the continuous certificate of joint paths.
* :mod:`gdnplan.arm3d.held`: an object held by the tool frame (the fetch's stick).
* :mod:`gdnplan.arm3d.ik3d`: end-effector pose IK (damped least squares, collision-free).
"""

from __future__ import annotations

from .builtin import load_robot3d, robot3d_names
from .ccd3d import Certificate3D, certify_path3d, lever_arms3d, motion_bound3d
from .cloud3d import cloud_obstacle, read_cloud
from .distance3d import (
    Checker3D,
    Coal3DModel,
    Distances3D,
    checker3d,
    signed_distance3d,
    signed_distance3d_and_grad,
)
from .held import hold
from .ik3d import PoseIK, frame_pose, solve_pose_ik, tool_frame
from .robot3d import LinkShape, Robot3D, robot3d_from_urdf
from .scene3d import (
    Obstacle3D,
    Scene3D,
    box_obstacle,
    capsule_obstacle,
    convex_obstacle,
    cylinder_obstacle,
    mesh_obstacle,
    obstacle,
    random_boxes,
    sphere_obstacle,
)

__all__ = [
    "Certificate3D",
    "Checker3D",
    "Coal3DModel",
    "Distances3D",
    "LinkShape",
    "Obstacle3D",
    "PoseIK",
    "Robot3D",
    "Scene3D",
    "box_obstacle",
    "capsule_obstacle",
    "certify_path3d",
    "checker3d",
    "cloud_obstacle",
    "convex_obstacle",
    "cylinder_obstacle",
    "frame_pose",
    "hold",
    "lever_arms3d",
    "load_robot3d",
    "mesh_obstacle",
    "motion_bound3d",
    "obstacle",
    "random_boxes",
    "read_cloud",
    "robot3d_from_urdf",
    "robot3d_names",
    "signed_distance3d",
    "signed_distance3d_and_grad",
    "solve_pose_ik",
    "sphere_obstacle",
    "tool_frame",
]
