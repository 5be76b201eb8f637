"""Bring your own robot: plan for a URDF arm, from a problem file and from Python.

python examples/04_user_urdf.py

``three_link_arm.urdf`` is a three-link arm moving in the world x–y plane (its tool_roll joint
turns out of the plane and is locked). The problem file ``three_link_arm.toml`` names it with
a path relative to itself, so ``gdnplan plan examples/three_link_arm.toml --collision coal``
works from any directory. There are no learned weights for your robot: plan with coal (or
train GraphDistNet for it first).
"""

from pathlib import Path

import numpy as np

import gdnplan as gp
from gdnplan.geometry import square

HERE = Path(__file__).resolve().parent

# 1. A problem file with [robot] urdf = "three_link_arm.urdf".
problem = gp.Problem.from_toml(HERE / "three_link_arm.toml")
result = gp.plan(problem, collision="coal")
robot = problem.scene.robot
print(
    f"problem file: robot {robot.name!r} ({robot.dof} joints {robot.joint_names}, "
    f"{robot.n_links} link polygons): certified {result.success}, "
    f"clearance ≥ {result.min_distance:+.4f} m, path cost {result.path_cost:.3f} rad²"
)

# 2. The same robot from Python: a RobotSpec, a scene and a problem with an end-effector goal.
spec = gp.RobotSpec(
    urdf=HERE / "three_link_arm.urdf",
    planning_joints=("shoulder", "elbow", "wrist"),
    locked={"tool_roll": np.pi / 2},
    plane_axes=((1.0, 0.0, 0.0), (0.0, 1.0, 0.0)),
)
arm = gp.robot_from_urdf("my_arm", spec)
scene = gp.Scene(arm, (square((0.9, 0.0), 0.2), square((-0.3, 0.7), 0.2)))
problem = gp.Problem(scene, start=[-1.2, 0.4, 0.0], goal_position=[0.2, 0.8])
result = gp.plan(problem, collision="coal")
print(
    f"python: robot {arm.name!r}, goal position reached: certified {result.success}, "
    f"clearance ≥ {result.min_distance:+.4f} m, final q {np.round(result.q[-1], 3).tolist()}"
)
