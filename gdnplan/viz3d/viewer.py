"""The meshcat viewer: load the robot and objects, send the animation, aim the camera."""

from __future__ import annotations

import contextlib
import sys
import time
import warnings
from collections.abc import Sequence

import numpy as np
import pinocchio as pin

from ..arm3d.scene3d import Scene3D
from ..errors import GdnplanError
from ..robot import Robot
from ..scene import Scene
from .frames import Frame, frame_poses
from .model import full_robot
from .viewer3d import send_plan3d

ROBOT_COLOR = (0.62, 0.68, 0.75, 1.0)  # rgba
INSTALL_HINT = "pip install 'gdnplan[viz3d]' (or: pip install meshcat)"


def require_meshcat():
    """The ``meshcat`` module, or a GdnplanError naming the pip command that installs it."""
    try:
        with warnings.catch_warnings():  # meshcat 0.3 imports pyzmq's deprecated ioloop
            warnings.simplefilter("ignore", DeprecationWarning)
            import meshcat
    except ImportError as e:
        raise GdnplanError(
            f"3-D view: meshcat is not installed; install it with {INSTALL_HINT}"
        ) from e
    return meshcat


def send_plan(
    viewer, segments: Sequence[tuple[Scene, np.ndarray]], per_segment: int = 4, fps: int = 20
) -> int:
    """Load the robot and the objects into a ``meshcat.Visualizer`` and send the animation.

    The robot's geometry goes under ``<robot name>/visuals``, the objects under ``scene``;
    the view shows the first frame and plays the animation once (the browser's Animations
    controls replay it). Returns the number of frames.
    """
    require_meshcat()
    from meshcat.animation import Animation
    from pinocchio.visualize import MeshcatVisualizer

    frames = frame_poses(segments, per_segment)
    robot = segments[0][0].robot
    full = full_robot(robot)
    viz = MeshcatVisualizer(full.model, visual_model=full.geometry)
    viz.initViewer(viewer=viewer)
    viz.loadViewerModel(rootNodeName=robot.name, visual_color=ROBOT_COLOR)
    paths = {
        g.name: viz.getViewerNodeName(g, pin.GeometryType.VISUAL)
        for g in full.geometry.geometryObjects
    }
    _load_objects(viewer, frames)
    animation = Animation(default_framerate=fps)
    for i, frame in enumerate(frames):
        with animation.at_frame(viewer, i) as node:
            _place(node, paths, frame)
    _place(viewer, paths, frames[0])
    _aim_camera(viewer, robot, frames[0])
    viewer.set_animation(animation, play=True)
    return len(frames)


def view_plan(
    segments: Sequence[tuple[Scene, np.ndarray]],
    zmq_url: str | None = None,
    per_segment: int = 4,
    fps: int = 20,
    wait: bool = True,
) -> str:
    """Show the robot following the paths in a meshcat browser view; returns its web URL.

    With ``zmq_url`` None a meshcat server is started for this process, so with ``wait`` the
    call blocks until Ctrl-C (the server ends with the process); with the ``zmq_url`` of a
    running ``meshcat-server`` it returns at once and the scene stays there. Messages go to
    stderr (stdout stays clean for ``--json``).

    Args:
        segments: (scene, path (T, dof)) pairs, as :func:`frame_poses`; for 3-D scenes
            (:class:`~gdnplan.arm3d.Scene3D`) the path may be a TimedTrajectory, and the
            plan goes to :func:`gdnplan.viz3d.viewer3d.send_plan3d`.
        zmq_url: e.g. ``"tcp://127.0.0.1:6000"``, or None to start a server.
        per_segment: frames per path segment.
        fps: animation frames per second.
        wait: block until Ctrl-C when this call started the server.
    """
    meshcat = require_meshcat()
    with contextlib.redirect_stdout(sys.stderr):
        viewer = meshcat.Visualizer(zmq_url)
    send = send_plan3d if segments and isinstance(segments[0][0], Scene3D) else send_plan
    n = send(viewer, segments, per_segment, fps)
    url = viewer.url()
    print(f"3-D view: {url} ({n} frames; the Animations panel replays them)", file=sys.stderr)
    if zmq_url is None and wait:
        print("3-D view: serving until Ctrl-C", file=sys.stderr)
        with contextlib.suppress(KeyboardInterrupt):
            while True:
                time.sleep(1.0)
    return url


def _load_objects(viewer, frames: list[Frame]) -> None:
    """Send each object's mesh once (its first appearance), under ``scene/<name>``."""
    import meshcat.geometry as mg

    sent: set[str] = set()
    for frame in frames:
        for name, prism in frame.objects.items():
            if name in sent:
                continue
            vertices, faces = prism.mesh()
            material = mg.MeshLambertMaterial(color=prism.color)
            viewer[f"scene/{name}"].set_object(mg.TriangularMeshGeometry(vertices, faces), material)
            sent.add(name)


def camera_placement(robot: Robot, frame: Frame) -> tuple[np.ndarray, np.ndarray]:
    """Orbit target (3,) and camera position (3,) (world, m) that face the robot's plane.

    The target is the centre of the frame's bounding box (robot geometry origins and object
    vertices); the camera stands 1.2 box diagonals away along the plane normal, raised by a
    third of that along v and shifted by a fifth along u.
    """
    points = np.vstack(
        [np.array([pose[:3, 3] for pose in frame.robot.values()])]
        + [prism.world_vertices() for prism in frame.objects.values()]
    )
    low, high = points.min(0), points.max(0)
    target, distance = (low + high) / 2, 1.2 * float(np.linalg.norm(high - low))
    axes = robot.plane.axes
    return target, target + distance * (robot.plane.normal + axes[1] / 3 + axes[0] / 5)


def _aim_camera(viewer, robot: Robot, frame: Frame) -> None:
    """Point meshcat's default camera (orbiting ``/Cameras/default``, y-up below it)."""
    target, position = camera_placement(robot, frame)
    pose = np.eye(4)
    pose[:3, 3] = target
    viewer["/Cameras/default"].set_transform(pose)
    x, y, z = position - target
    viewer["/Cameras/default/rotated/<object>"].set_property("position", [x, z, -y])


def _place(node, paths: dict[str, str], frame: Frame) -> None:
    """Set every robot geometry's and object's transform on a viewer or an animation frame."""
    for name, pose in frame.robot.items():
        node[paths[name]].set_transform(pose)
    for name, prism in frame.objects.items():
        node[f"scene/{name}"].set_transform(prism.pose)
