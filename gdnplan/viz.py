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
