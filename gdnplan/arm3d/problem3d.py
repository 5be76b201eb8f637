"""Random 3-D reaching problems: the 3-D counterpart of the planar environment (d) benchmark.

Problem i of :func:`reaching_problems` is the robot among ``boxes`` random boxes
(:func:`~gdnplan.arm3d.random_boxes`, scene seed ``seed + i``) with a start and a goal drawn
uniformly within the joint limits such that

* both lie in the problem's joint box: the robot's limits cut to [−``joint_range``,
  ``joint_range``] (π by default: the UR5e's ±2π joints would make the joint space 32 times
  the volume of the ±π box for the same obstacles; the Panda's limits lie within it), which
  is also the box the planner searches (``Problem.lower``/``upper``);
* both are clear of the margin: exact signed distance (obstacles and self-collision) > margin
  (and the proven bound above it, as :class:`~gdnplan.trajopt.Problem` demands), and
* the straight joint-space line between them collides: one of ``LINE_SAMPLES`` evenly spaced
  configurations on it has a signed distance ≤ 0 (a witnessed collision, so the planner has
  to go around).

Box sides and the boxes' clearance from the base's vertical axis (:data:`BOXES`) are chosen
per robot so that about 25–40 % of uniformly random configurations collide, as in environment
(d) (:func:`collision_fraction` measures it; the Panda's thinner links need larger boxes, kept
farther from its base so that no box overlaps its first links at every configuration).
"""

from __future__ import annotations

import math

import numpy as np

from ..ccd import proven_distance
from ..errors import InputError
from ..limits import check_int, check_number
from ..robot_checks import make_rng
from ..trajopt.problem import Problem
from .builtin import load_robot3d
from .distance3d import checker3d, signed_distance3d
from .robot3d import Robot3D
from .scene3d import Scene3D, random_boxes

# robot -> ((smallest, largest) box side, box centres' distance from the base axis), m
BOXES = {"ur5e": ((0.05, 0.2), 0.25), "panda": ((0.15, 0.3), 0.35), "ur5": ((0.05, 0.2), 0.25)}
LINE_SAMPLES = 50  # configurations on the straight line searched for a collision
MAX_DRAWS = 2000  # (start, goal) draws per problem before giving up


def reaching_scene(robot: Robot3D | str, seed: int, boxes: int = 20) -> Scene3D:
    """The robot among ``boxes`` random boxes of its :data:`BOXES` (scene seed ``seed``)."""
    robot = load_robot3d(robot) if isinstance(robot, str) else robot
    size, clearance = BOXES.get(robot.name, BOXES["ur5e"])
    return random_boxes(robot, boxes, seed=seed, size=size, base_clearance=clearance)


def collision_fraction(scene: Scene3D, n: int = 500, seed: int = 0) -> float:
    """Share of ``n`` uniformly random configurations in collision (signed distance ≤ 0)."""
    robot = scene.robot
    q = robot.random_configurations(check_int(n, "n", 1, 10**6), make_rng(seed))
    return float(np.mean(signed_distance3d(scene, q) <= 0))


def _draw_pair(scene: Scene3D, rng: np.random.Generator, margin: float, box):
    """(start, goal) in the joint box clear of the margin with a colliding straight line, or
    None."""
    s = np.linspace(0.0, 1.0, LINE_SAMPLES)[:, None]
    swept = checker3d(scene).swept_max
    for _ in range(MAX_DRAWS):
        ends = rng.uniform(box[0], box[1], (2, len(box[0])))
        d = checker3d(scene).evaluate(ends, contact_offset=margin).distance  # contact-only: d ≥ 0
        if np.any(d <= margin) or np.any(proven_distance(d, swept) <= margin):
            continue
        line = ends[0] + s * (ends[1] - ends[0])
        if np.min(signed_distance3d(scene, line)) <= 0.0:
            return ends[0], ends[1]
    return None


def reaching_problems(
    robot: Robot3D | str,
    n: int = 20,
    seed: int = 0,
    boxes: int = 20,
    margin: float = 0.02,
    waypoints: int = 20,
    joint_range: float = math.pi,
) -> list[Problem]:
    """``n`` random feasible reaching problems for ``robot`` (a name or a Robot3D); see the
    module. Deterministic for a seed. InputError when a scene admits no such pair."""
    check_int(n, "n", 1, 10_000)
    check_number(margin, "margin")
    check_number(joint_range, "joint_range", strict=True)
    robot = load_robot3d(robot) if isinstance(robot, str) else robot
    box = (np.maximum(robot.lower, -joint_range), np.minimum(robot.upper, joint_range))
    problems = []
    for i in range(n):
        scene = reaching_scene(robot, seed + i, boxes)
        pair = _draw_pair(scene, np.random.default_rng([seed, i]), margin, box)
        if pair is None:
            raise InputError(
                f"reaching problem {i}: no start/goal pair in {MAX_DRAWS} draws; use fewer boxes"
            )
        problems.append(
            Problem(
                scene,
                pair[0],
                goal=pair[1],
                waypoints=waypoints,
                margin=margin,
                lower=box[0],
                upper=box[1],
            )
        )
    return problems


__all__ = ["BOXES", "collision_fraction", "reaching_problems", "reaching_scene"]
