"""Animated GIF of a 3-D plan (headless matplotlib): the arm, the obstacles, the clearance.

The 3-D counterpart of :func:`gdnplan.viz.animate_paths`. Left: the robot's link shapes and the
obstacles as the triangle meshes of :mod:`gdnplan.viz3d.meshes` (the geometry coal checks, a
held object included) in one ``Poly3DCollection``, depth-sorted by matplotlib and shaded by
|n · l| (n the triangle's unit normal, l a fixed light direction); the tool frame's trace
(green) and the witness segment of the current clearance (black: the closest pair's witness
points, obstacles or self-collision). Right: the exact clearance (coal, self-collision
included) along the whole path, the margin as a red dashed line, the current frame as a dot.

A stage is ``(scene, path)`` with ``path`` the waypoints (T, dof) (rad), played along the
piecewise-linear path the certificate proves against the waypoint index, or a
:class:`gdnplan.timing.TimedTrajectory`, played at its own times (s). The axis limits hold
every frame's robot and every obstacle; the camera looks across the tool's main horizontal
direction of motion (the trace's principal axis), from the side the arm reaches to.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure
from matplotlib.ticker import MaxNLocator

from ..arm3d.distance3d import checker3d
from ..arm3d.held import HELD_LINK
from ..arm3d.scene3d import Scene3D
from ..errors import InputError
from ..files import atomic_path
from ..limits import check_int
from ..timing import TimedTrajectory
from .meshes import obstacle_triangles, robot_triangles, tool_positions

ROBOT_RGB = np.array([0.90, 0.42, 0.10])  # orange links
TOOL_RGB = np.array([0.45, 0.20, 0.06])  # the tool body (gripper, hand, fingers)
HELD_RGB = np.array([0.85, 0.65, 0.13])  # a held object
OBSTACLE_RGBA = np.array([0.30, 0.50, 0.75, 0.30])  # see-through blue
LIGHT = np.array([0.35, -0.45, 0.82]) / np.linalg.norm([0.35, -0.45, 0.82])
CLEARANCE_SAMPLES = 200  # exact distances per stage for the clearance panel
ELEVATION = 28.0  # degrees
ZOOM = 1.0  # mplot3d box zoom
MAX_FRAMES = 2000  # frames of one GIF at most (each is kept in memory until written)
PALETTE_COLORS = 128  # GIF palette size, shared by all frames


def _samples(path, n: int) -> tuple[np.ndarray, np.ndarray]:
    """(x (n,), q (n, dof)): times (s) of a TimedTrajectory, or waypoint positions s ∈ [0, T−1]
    of a path (T, dof) with q on the straight segments between waypoints."""
    if isinstance(path, TimedTrajectory):
        t = np.linspace(0.0, path.duration, n)
        return t, path.evaluate(t)[0]
    q = np.asarray(path, float)
    s = np.linspace(0.0, len(q) - 1, n)
    k = np.minimum(np.floor(s).astype(int), max(len(q) - 2, 0))
    frac = (s - k)[:, None]
    q_next = q[np.minimum(k + 1, len(q) - 1)]
    return s, q[k] + frac * (q_next - q[k])


def _robot_colors(scene: Scene3D, owner: np.ndarray) -> np.ndarray:
    """(F, 3) base colour of each robot triangle (shape index ``owner``)."""
    robot = scene.robot
    tool_body = max(s.body for s in robot.shapes)
    table = np.array(
        [
            HELD_RGB if s.link == HELD_LINK else TOOL_RGB if s.body == tool_body else ROBOT_RGB
            for s in robot.shapes
        ]
    )
    return table[owner]


def _shade(tris: np.ndarray, rgb: np.ndarray) -> np.ndarray:
    """(F, 3) colours scaled by 0.45 + 0.55 |n · LIGHT| (two-sided: mesh winding is free)."""
    normal = np.cross(tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0])
    normal /= np.maximum(np.linalg.norm(normal, axis=1, keepdims=True), 1e-12)
    return rgb * (0.45 + 0.55 * np.abs(normal @ LIGHT))[:, None]


def _view_azimuth(tool: np.ndarray) -> float:
    """Azimuth (degrees) perpendicular to the trace's main horizontal axis, on the side of the
    trace's mean position (seen from the base's vertical axis)."""
    xy = tool[:, :2] - tool[:, :2].mean(0)
    axis = np.linalg.svd(xy, full_matrices=False)[2][0] if np.any(xy) else np.array([1.0, 0.0])
    side = np.array([-axis[1], axis[0]])
    if side @ tool[:, :2].mean(0) < 0:
        side = -side
    return float(np.degrees(np.arctan2(side[1], side[0])))


def animate_paths3d(
    stages: Sequence[tuple[Scene3D, np.ndarray | TimedTrajectory]],
    out: str | Path,
    frames: int = 60,
    fps: int = 12,
    title: str = "",
    margin: float | None = None,
    dpi: int = 100,
) -> int:
    """Write a GIF of 3-D robots following their paths, with the exact clearance along them.

    Args:
        stages: (scene, path) pairs played one after the other; ``path`` is waypoints
            (T, dof) in rad or a :class:`~gdnplan.timing.TimedTrajectory`. All stages are
            timed or none (the clearance panel's x axis: time in s, or the waypoint index).
        out: the ``.gif`` path (written atomically).
        frames: frames in all (≥ 2 per stage, ≤ ``MAX_FRAMES``), shared by the stages by
            their length (duration, or waypoint segments).
        fps: frames per second, 1 to 100 (the last frame is held for a second).
        title: the figure's title.
        margin: the clearance the plan had to keep (m), drawn as a red dashed line.
        dpi: pixels per inch of the 10 × 5 inch figure, 10 to 400.

    Returns:
        The number of frames written.
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection
    from PIL import Image

    if not stages:
        raise InputError("animate: no path to show")
    timed = {isinstance(p, TimedTrajectory) for _, p in stages}
    if len(timed) != 1:
        raise InputError("animate: give every stage a TimedTrajectory, or none")
    timed = timed.pop()
    for scene, _ in stages:
        if not isinstance(scene, Scene3D):
            raise InputError(f"animate: expected a Scene3D, got {type(scene).__name__}")
    check_int(frames, "frames", 2 * len(stages), MAX_FRAMES)
    check_int(fps, "fps", 1, 100)
    check_int(dpi, "dpi", 10, 400)
    lengths = np.array([p.duration if timed else len(np.asarray(p)) - 1 for _, p in stages], float)
    share = lengths / lengths.sum() if lengths.sum() > 0 else np.full(len(stages), 1 / len(stages))
    counts = np.maximum(2, np.round(share * frames).astype(int))
    counts[np.argmax(counts)] += frames - counts.sum()

    offset, dense_x, dense_d, trace, rows = 0.0, [], [], [], []
    for (scene, path), n in zip(stages, counts, strict=True):
        x, q = _samples(path, int(n))
        xd, qd = _samples(path, CLEARANCE_SAMPLES)
        res = checker3d(scene).evaluate(q)
        tris, owner = robot_triangles(scene.robot, q)
        obstacles, _ = obstacle_triangles(scene)
        colors = _robot_colors(scene, owner)
        tool = tool_positions(scene.robot, q)
        dense_x.append(xd + offset)
        dense_d.append(checker3d(scene).evaluate(qd).distance)
        trace.append(tool_positions(scene.robot, qd))
        for i in range(len(q)):
            rows.append((x[i] + offset, res.distance[i], res.point1[i], res.point2[i],
                         tool[i], tris[i], colors, obstacles))  # fmt: skip
        offset += float(x[-1])
    dense_x, dense_d, trace = map(np.concatenate, (dense_x, dense_d, trace))

    points = np.concatenate([np.vstack([r[5].reshape(-1, 3), r[7].reshape(-1, 3)]) for r in rows])
    low, high = points.min(0), points.max(0)
    pad = 0.05 * float(np.max(high - low))
    low, high = low - pad, high + pad

    fig = Figure(figsize=(10, 5), dpi=dpi)
    canvas = FigureCanvasAgg(fig)
    ax = fig.add_axes((0.0, 0.09, 0.66, 0.8), projection="3d", computed_zorder=False)
    ax.set_xlim(low[0], high[0])
    ax.set_ylim(low[1], high[1])
    ax.set_zlim(low[2], high[2])
    ax.set_box_aspect(high - low, zoom=ZOOM)
    ax.view_init(elev=ELEVATION, azim=_view_azimuth(trace))
    for name, axis in zip("xyz", (ax.xaxis, ax.yaxis, ax.zaxis), strict=True):
        axis.set_major_locator(MaxNLocator(4))
        axis.set_label_text(f"{name} (m)", fontsize=8)
    ax.tick_params(labelsize=7, pad=0)
    mesh = Poly3DCollection([], linewidths=0.0)
    ax.add_collection3d(mesh)
    (path_line,) = ax.plot(*trace.T, "-", color="tab:green", linewidth=1.5)
    (tip,) = ax.plot([], [], [], "o", color="tab:green", markersize=5)
    (witness,) = ax.plot([], [], [], "k.-", linewidth=1.2, markersize=4)
    label = fig.text(0.04, 0.9, "", fontsize=9)

    side = fig.add_axes((0.71, 0.14, 0.27, 0.70))
    side.plot(dense_x, dense_d, "k-", linewidth=1)
    if margin is not None:
        side.axhline(margin, color="tab:red", linestyle="--", linewidth=1, label="margin")
        side.legend(fontsize=8, loc="lower right")
    side.axhline(0.0, color="0.6", linewidth=0.8)
    side.set_xlabel("time (s)" if timed else "waypoint")
    side.set_ylabel("coal clearance (m)")
    side.grid(alpha=0.3)
    (marker,) = side.plot([], [], "o", color="tab:red")
    fig.suptitle(title)
    moving = (mesh, path_line, tip, witness, label, marker)
    for artist in moving:  # drawn on a copy of the static rest (axes, panes, ticks, curve)
        artist.set_animated(True)
    canvas.draw()
    background = canvas.copy_from_bbox(fig.bbox)

    images, palette = [], None
    for x, d, p1, p2, tool, tris, colors, obstacles in rows:
        shaded = _shade(tris, colors)
        rgba = np.vstack(
            [
                np.column_stack([shaded, np.ones(len(shaded))]),
                np.column_stack([_shade(obstacles, OBSTACLE_RGBA[:3]),
                                 np.full(len(obstacles), OBSTACLE_RGBA[3])]),
            ]
        )  # fmt: skip
        mesh.set_verts(np.concatenate([tris, obstacles]))
        mesh.set_facecolor(rgba)
        tip.set_data_3d([tool[0]], [tool[1]], [tool[2]])
        witness.set_data_3d(*np.stack([p1, p2]).T)
        marker.set_data([x], [d])
        at = f"t = {x:.2f} s" if timed else f"waypoint {x:.1f}"
        label.set_text(f"{at}: clearance {d:+.3f} m")
        canvas.restore_region(background)
        mesh.do_3d_projection()
        for artist in moving:
            artist.axes.draw_artist(artist) if artist.axes else fig.draw_artist(artist)
        image = Image.frombuffer("RGBA", canvas.get_width_height(), canvas.buffer_rgba())
        image = image.convert("RGB")
        if palette is None:  # one palette for all frames: fast, no flicker between frames
            palette = image.quantize(colors=PALETTE_COLORS, method=Image.Quantize.MEDIANCUT)
        images.append(image.quantize(palette=palette, dither=Image.Dither.NONE))
    durations = [round(1000 / fps)] * (len(images) - 1) + [1000]
    with atomic_path(out, "--animate") as tmp:
        images[0].save(
            tmp, format="GIF", save_all=True, append_images=images[1:], duration=durations, loop=0
        )
    return len(images)
