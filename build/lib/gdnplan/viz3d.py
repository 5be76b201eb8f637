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

Needs ``pip install meshcat`` (the ``viz3d`` extra); :func:`scene_objects`,
:func:`full_robot` and :func:`frame_poses` are pure and work without it.
"""

from __future__ import annotations

import contextlib
import sys
import time
import warnings
from collections.abc import Sequence
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import numpy as np
import pinocchio as pin

from .errors import GdnplanError, InputError
from .robot import Robot
from .scene import Scene
from .ur5e import BODY_LENGTH, GRASP_GAP
from .viz import interpolate_path

DEPTH = 0.4  # m: out-of-plane depth of the extruded obstacles
ROBOT_COLOR = (0.62, 0.68, 0.75, 1.0)  # rgba
COLORS = {"storage": 0x9C7A54, "table": 0x8C8C8C, "stick": 0xDAA520}  # 0xRRGGBB by name
OBSTACLE_COLOR = 0x4A7FB5
INSTALL_HINT = "pip install 'gdnplan[viz3d]' (or: pip install meshcat)"


# -------------------------------------------------------------------- scene objects
@dataclass(frozen=True)
class Prism:
    """A convex polygon extruded along its frame's z axis (an obstacle part or the stick).

    Attributes:
        name: viewer name, e.g. ``"storage/3"`` or ``"stick"``.
        polygon: (m, 2) CCW vertices in the frame's x–y plane (m).
        depth: extent along the frame's z, centred on z = 0 (m).
        pose: (4, 4) homogeneous transform frame → world.
        color: 0xRRGGBB.
    """

    name: str
    polygon: np.ndarray
    depth: float
    pose: np.ndarray
    color: int

    def mesh(self) -> tuple[np.ndarray, np.ndarray]:
        """Triangle mesh in the frame: vertices (2m, 3) (bottom ring, then top) and
        outward-facing CCW faces (4m − 4, 3)."""
        m = len(self.polygon)
        half = np.full((m, 1), self.depth / 2)
        vertices = np.vstack([np.hstack([self.polygon, -half]), np.hstack([self.polygon, half])])
        fan = np.arange(1, m - 1)
        top = np.stack([np.full(m - 2, m), m + fan, m + fan + 1], 1)
        bottom = np.stack([np.zeros(m - 2, int), fan + 1, fan], 1)
        i, j = np.arange(m), (np.arange(m) + 1) % m
        sides = np.vstack([np.stack([i, j, m + j], 1), np.stack([i, m + j, m + i], 1)])
        return vertices, np.vstack([bottom, top, sides])

    def world_vertices(self) -> np.ndarray:
        """(2m, 3) mesh vertices in world coordinates (m)."""
        vertices = self.mesh()[0]
        return vertices @ self.pose[:3, :3].T + self.pose[:3, 3]


def tool_offset(robot: Robot) -> float:
    """Out-of-plane coordinate (m, along the plane normal) of the robot's tool frame.

    The tool frame is ``robot.info["tcp_frame"]`` or the model's last frame; planar motion
    keeps its offset constant, so it is evaluated at q = 0.
    """
    model = robot.model
    data = model.createData()
    pin.framesForwardKinematics(model, data, np.zeros(robot.dof))
    name = robot.info.get("tcp_frame", model.frames[model.nframes - 1].name)
    point = data.oMf[model.getFrameId(name)].translation
    return float(robot.plane.normal @ (point - robot.plane.origin))


def _plane_pose(robot: Robot, uv: np.ndarray, offset: float) -> np.ndarray:
    """(4, 4) frame at plane point ``uv`` (2,), ``offset`` along the normal, axes (u, v, n)."""
    plane = robot.plane
    pose = np.eye(4)
    pose[:3, :3] = np.column_stack([plane.axes[0], plane.axes[1], plane.normal])
    pose[:3, 3] = plane.lift(uv) + offset * plane.normal
    return pose


def _obstacle_names(scene: Scene) -> list[str]:
    """Name of each obstacle: its key in ``scene.info`` (storage, table, stick) or obstacle<i>."""
    names = []
    for i, poly in enumerate(scene.obstacles):
        named = [
            key
            for key in COLORS
            if np.shape(scene.info.get(key)) == poly.shape and np.allclose(scene.info[key], poly)
        ]
        names.append(named[0] if named else f"obstacle{i}")
    return names


def scene_objects(scene: Scene, depth: float = DEPTH) -> list[Prism]:
    """The scene's obstacles as 3-D prisms, one per convex part (what coal checks).

    Each part is centred on its vertex mean (in its frame's x–y = the plane's u–v) and
    extruded by ``depth`` (m) about the tool's out-of-plane offset (:func:`tool_offset`); a
    fetch stick is ``stick_width`` deep. Names: the obstacle's name, with ``/k`` for its k-th
    part when it has several.
    """
    offset = tool_offset(scene.robot)
    names = _obstacle_names(scene)
    counts = np.bincount(scene.part_owner, minlength=len(names))
    seen: dict[int, int] = {}
    objects = []
    for part, owner in zip(scene.obstacle_parts, scene.part_owner, strict=True):
        k = seen[owner] = seen.get(owner, -1) + 1
        name = names[owner]
        centre = part.mean(0)
        objects.append(
            Prism(
                name=name if counts[owner] == 1 else f"{name}/{k}",
                polygon=part - centre,
                depth=scene.info["stick_width"] if name == "stick" else depth,
                pose=_plane_pose(scene.robot, centre, offset),
                color=COLORS.get(name, OBSTACLE_COLOR),
            )
        )
    return objects


# -------------------------------------------------------------------- the full robot
@dataclass(frozen=True, eq=False)
class FullRobot:
    """The full Pinocchio model of a planar robot, its non-planning joints locked.

    Attributes:
        model: the full model (every joint of the URDF).
        geometry: its collision geometry (the URDF's, without a held stick).
        q_locked: (nq,) full configuration with the planning joints at 0 (rad or m).
        planning_index: (dof,) index of each planning joint in the full configuration.
    """

    model: pin.Model
    geometry: pin.GeometryModel
    q_locked: np.ndarray
    planning_index: np.ndarray

    def configuration(self, q: np.ndarray) -> np.ndarray:
        """(nq,) full configuration of the planar configuration q (dof,)."""
        full = self.q_locked.copy()
        full[self.planning_index] = q
        return full

    def placements(self, q: np.ndarray) -> tuple[pin.Data, pin.GeometryData]:
        """Frame and geometry placements (``data.oMf``, ``geometry_data.oMg``) at q (dof,)."""
        data, gdata = self.model.createData(), pin.GeometryData(self.geometry)
        pin.framesForwardKinematics(self.model, data, self.configuration(q))
        pin.updateGeometryPlacements(self.model, data, self.geometry, gdata)
        return data, gdata


def _locked_value(full: pin.Model, data: pin.Data, j: int, reduced_pose: pin.SE3) -> float:
    """Value of the 1-dof joint j of ``full`` whose frame sits at ``reduced_pose``.

    With the parent placed by ``data``: M_j(q_j) = (oMi[parent] · jointPlacement)⁻¹ · pose, and
    q_j = Sᵀ log6(M_j) / |S|² with S (6,) the joint's motion subspace (rotation or slide axis).
    """
    joint = full.joints[j]
    if joint.nq != 1 or joint.nv != 1:
        raise InputError(f"3-D view: joint {full.names[j]!r} is not a 1-dof joint")
    motion = (data.oMi[full.parents[j]] * full.jointPlacements[j]).inverse() * reduced_pose
    jdata = joint.createData()
    joint.calc(jdata, np.zeros(1))
    axis = np.asarray(jdata.S).reshape(6)
    return float(axis @ pin.log6(motion).vector / (axis @ axis))


@lru_cache(maxsize=8)
def full_robot(robot: Robot) -> FullRobot:
    """The full model of ``robot`` (from ``robot.info["urdf"]``) with its locked joints' values.

    Each locked joint's value is recovered from the reduced model (``robot.model``), where
    Pinocchio keeps the joint as a fixed frame of the same name placed at its locked value.
    ``package://`` mesh paths resolve against the URDF's parent folders.
    """
    urdf = Path(robot.info.get("urdf", ""))
    if not urdf.is_file():
        raise InputError(f"3-D view: robot {robot.name!r} has no URDF file ({urdf})")
    model = pin.buildModelFromUrdf(str(urdf))
    packages = [str(p) for p in urdf.resolve().parents]  # package:// meshes, as ROS lays them
    geometry = pin.buildGeomFromUrdf(
        model, str(urdf), pin.GeometryType.COLLISION, package_dirs=packages
    )
    reduced = robot.model
    rdata = reduced.createData()
    pin.framesForwardKinematics(reduced, rdata, np.zeros(robot.dof))
    q, data = pin.neutral(model), model.createData()
    planning = robot.joint_names
    for j in range(1, model.njoints):
        if model.names[j] in planning:
            continue
        pin.forwardKinematics(model, data, q)
        pose = rdata.oMf[reduced.getFrameId(model.names[j])]
        q[model.joints[j].idx_q] = _locked_value(model, data, j, pose)
    index = np.array([model.joints[model.getJointId(n)].idx_q for n in planning])
    return FullRobot(model, geometry, q, index)


def held_stick(robot: Robot, data: pin.Data, full: FullRobot) -> Prism | None:
    """The stick the robot holds (None when it holds none), placed by ``data.oMf`` of ``full``.

    Its frame has x along the stick (the tool axis), y across it in the plane (the opening
    direction), z out of the plane, like the obstacle stick of :func:`scene_objects`.
    """
    if "stick_length" not in robot.info:
        return None
    length, width = robot.info["stick_length"], robot.info["stick_width"]
    gripper = data.oMf[full.model.getFrameId("gripper_base_link")]
    local = np.eye(4)
    local[:3, :3] = np.array([[0.0, 0.0, -1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]])  # x→z, z→−x
    local[2, 3] = BODY_LENGTH + GRASP_GAP + length / 2
    rectangle = np.array([[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]])
    return Prism(
        name="stick",
        polygon=rectangle * np.array([length / 2, width / 2]),
        depth=width,
        pose=gripper.homogeneous @ local,
        color=COLORS["stick"],
    )


# -------------------------------------------------------------------- frames
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


# -------------------------------------------------------------------- the viewer
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
        segments: (scene, path (T, dof)) pairs, as :func:`frame_poses`.
        zmq_url: e.g. ``"tcp://127.0.0.1:6000"``, or None to start a server.
        per_segment: frames per path segment.
        fps: animation frames per second.
        wait: block until Ctrl-C when this call started the server.
    """
    meshcat = require_meshcat()
    with contextlib.redirect_stdout(sys.stderr):
        viewer = meshcat.Visualizer(zmq_url)
    n = send_plan(viewer, segments, per_segment, fps)
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
