"""Matplotlib figures: scenes with the robot and the coal witness segment."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.patches import Polygon as PolygonPatch

from .distance import witness
from .scene import Scene

ROBOT_COLOR = "tab:red"
OBSTACLE_COLOR = "tab:blue"


def draw_polygons(ax: Axes, polygons, color: str, alpha: float = 0.5, **kwargs) -> None:
    """Filled polygons (m, 2) on an axis."""
    for poly in polygons:
        ax.add_patch(
            PolygonPatch(poly, closed=True, facecolor=color, edgecolor=color, alpha=alpha, **kwargs)
        )


def draw_scene(
    ax: Axes, scene: Scene, q: np.ndarray | None = None, show_witness: bool = True
) -> float | None:
    """Obstacles, the robot at q (if given) and the witness segment of the signed distance.

    Returns the signed distance at q (m), or None without q.
    """
    draw_polygons(ax, scene.obstacles, OBSTACLE_COLOR)
    ax.plot(*scene.robot.chain.joint_origins[0], "k^", markersize=8)
    lim = scene.robot.reach + 0.2
    ax.set_xlim(-lim, lim)
    ax.set_ylim(-lim, lim)
    ax.set_aspect("equal")
    ax.grid(alpha=0.3)
    if q is None:
        return None
    draw_polygons(ax, scene.robot.link_polygons(q), ROBOT_COLOR, alpha=0.7)
    d, p_robot, p_obstacle = witness(scene, q)
    if show_witness:
        ax.plot(*np.stack([p_robot, p_obstacle]).T, "k.-", linewidth=1.5)
        state = "free" if d > 0 else "in collision"
        ax.set_title(f"{scene.name}: signed distance {d:+.4f} m ({state})")
    return d


def scene_figure(scene: Scene, q: np.ndarray | None = None) -> Figure:
    """A standalone figure of :func:`draw_scene`."""
    fig = Figure(figsize=(6, 6))
    draw_scene(fig.add_subplot(), scene, q)
    fig.tight_layout()
    return fig


def save_figure(fig: Figure, path) -> None:
    """Write a figure atomically: render to a temporary file beside ``path``, then rename."""
    path = Path(path)
    tmp = path.with_name(f".{path.name}.tmp{path.suffix}")
    fig.savefig(tmp, dpi=120)
    os.replace(tmp, path)


def interpolate_path(q_path: np.ndarray, per_segment: int) -> np.ndarray:
    """Linear interpolation of a path (T, dof) with ``per_segment`` steps per segment.

    Returns ((T − 1) · per_segment + 1, dof) configurations, the waypoints included.
    """
    q_path = np.asarray(q_path, dtype=float)
    t = np.arange(per_segment)[:, None] / per_segment
    inner = q_path[:-1, None] + t[None] * (q_path[1:] - q_path[:-1])[:, None]
    return np.concatenate([inner.reshape(-1, q_path.shape[1]), q_path[-1:]])


def animate_paths(
    stages: list[tuple[Scene, np.ndarray]],
    out,
    per_segment: int = 3,
    fps: int = 12,
    title: str = "",
) -> None:
    """GIF of the robot following one or more paths, with the coal clearance over time.

    Args:
        stages: (scene, path (T, dof)) pairs played one after the other; the scene may change
            between stages (e.g. the gripper closes on an object).
        out: output ``.gif`` path (written atomically).
        per_segment: frames per path segment.
        fps: frames per second.
        title: figure title.
    """
    from matplotlib.animation import FuncAnimation, PillowWriter

    from .distance import signed_distance

    frames = []  # (stage index, q)
    for s, (_, path) in enumerate(stages):
        frames += [(s, q) for q in interpolate_path(path, per_segment)]
    clearance = np.concatenate(
        [signed_distance(scene, interpolate_path(path, per_segment)) for scene, path in stages]
    )
    fig = Figure(figsize=(10, 4.8))
    ax_scene, ax_clear = fig.add_subplot(1, 2, 1), fig.add_subplot(1, 2, 2)
    ax_clear.plot(clearance, "k-", linewidth=1)
    ax_clear.axhline(0.0, color="tab:red", linewidth=1)
    ax_clear.set_xlabel("frame")
    ax_clear.set_ylabel("coal clearance (m)")
    ax_clear.grid(alpha=0.3)
    (marker,) = ax_clear.plot([], [], "o", color="tab:red")
    fig.suptitle(title)

    def draw(i: int):
        s, q = frames[i]
        ax_scene.clear()
        draw_scene(ax_scene, stages[s][0], q, show_witness=True)
        marker.set_data([i], [clearance[i]])
        return ()

    anim = FuncAnimation(fig, draw, frames=len(frames), blit=False)
    out = Path(out)
    tmp = out.with_name(f".{out.name}.tmp.gif")
    anim.save(tmp, writer=PillowWriter(fps=fps))
    os.replace(tmp, out)
