"""Animation frames: world poses of the robot's geometry and the objects along paths."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from ..scene import Scene
from ..viz import interpolate_path
from .model import full_robot, held_stick
from .objects import Prism, scene_objects


@dataclass(frozen=True)
class Frame:
    """One animation frame: 4×4 world poses of the robot's geometry and of the objects.

    Attributes:
        robot: geometry object name → (4, 4) pose.
        objects: object name → prism (its pose included).
    """

    robot: dict[str, np.ndarray]
    objects: dict[str, Prism]


def frame_poses(segments: Sequence[tuple[Scene, np.ndarray]], per_segment: int = 4) -> list[Frame]:
    """Frames of the robot following one or more paths, as :func:`gdnplan.viz.animate_paths`.

    Args:
        segments: (scene, path (T, dof)) pairs played one after the other; all scenes' robots
            must share one URDF (the gripper state may change, e.g. when it closes on a stick).
        per_segment: frames per path segment.

    Returns:
        ((T − 1) · per_segment + 1 per segment) frames; an object missing from a later
        segment's scene keeps its last pose.
    """
    if not segments:
        raise InputError("3-D view: no path to show")
    urdfs = {scene.robot.info.get("urdf") for scene, _ in segments}
    if len(urdfs) != 1:
        raise InputError(f"3-D view: all segments must share one robot URDF, got {sorted(urdfs)}")
    frames = []
    for scene, path in segments:
        full = full_robot(scene.robot)
        static = {p.name: p for p in scene_objects(scene)}
        names = [g.name for g in full.geometry.geometryObjects]
        for q in interpolate_path(scene.robot.check_q(path, "path"), per_segment):
            data, gdata = full.placements(q)
            robot = {n: gdata.oMg[g].homogeneous for g, n in enumerate(names)}
            stick = held_stick(scene.robot, data, full)
            objects = static if stick is None else {**static, "stick": stick}
            frames.append(Frame(robot, objects))
    return frames
