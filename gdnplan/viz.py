"""Matplotlib figures: scenes with the robot and the coal witness segment."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.patches import Polygon as PolygonPatch

from .distance import witness
from .errors import InputError
from .files import atomic_path
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
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=120)


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
    with atomic_path(out) as tmp:
        anim.save(tmp, writer=PillowWriter(fps=fps))


# -------------------------------------------------------------------- Table I figures
def distance_field(
    model,
    scene: Scene,
    n: int = 101,
    lim: float = np.pi,
    progress: Callable[[int], object] | None = None,
    chunk: int = 8192,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A 2-DoF model's value over the grid (q1, q2) ∈ [−lim, lim]²: (q1 (n,), q2 (n,), D (n, n)).

    ``D[i, j]`` is the value at (q1[j], q2[i]) (m for distances, a score for DiffCo). The n²
    configurations are evaluated ``chunk`` at a time, ``progress(k)`` called after each chunk
    of k (e.g. a tqdm bar's ``update``).
    """
    if scene.robot.dof != 2:
        raise InputError(f"scene: the field needs a 2-DoF robot, got {scene.robot.dof} joints")
    axis = np.linspace(-lim, lim, n)
    g1, g2 = np.meshgrid(axis, axis)
    q = np.stack([g1.ravel(), g2.ravel()], 1)
    parts = []
    for start in range(0, len(q), chunk):
        parts.append(model.distance(scene, q[start : start + chunk]))
        if progress is not None:
            progress(len(parts[-1]))
    return axis, axis, np.concatenate(parts).reshape(n, n)


def end_effector(robot, q: np.ndarray) -> np.ndarray:
    """(T, 2) midpoint of the last link's two nodes farthest from its joint (the arm's tip)."""
    last = np.flatnonzero(robot.node_polygon == robot.n_links - 1)
    lever = np.linalg.norm(robot.nodes0[last] - robot.chain.joint_origins[-1], axis=1)
    tip = last[np.argsort(lever)[-2:]]
    return robot.node_positions(q)[:, tip].mean(1)


def field_figure(
    scene: Scene,
    fields: dict[str, tuple[np.ndarray, np.ndarray, np.ndarray]],
    path_q: np.ndarray | None = None,
) -> Figure:
    """The paper's Fig. 5: the scene with the arm's trail, then one panel per field.

    Each field panel shows the value (blue = collision side, red = free side, centred on the
    zero level) with contour lines, the zero level in black and the joint path ``path_q``
    (T, 2) in green.
    """
    fig = Figure(figsize=(4.2 * (len(fields) + 1), 4.2))
    ax = fig.add_subplot(1, len(fields) + 1, 1)
    draw_scene(ax, scene, None)
    if path_q is not None:
        for q in path_q[:: max(len(path_q) // 8, 1)]:
            draw_polygons(ax, scene.robot.link_polygons(q), ROBOT_COLOR, alpha=0.15)
        tip = end_effector(scene.robot, path_q)
        ax.plot(tip[:, 0], tip[:, 1], "g-", linewidth=2)
    ax.set_title(f"({chr(97)}) env {scene.name}: arm trail")
    for k, (name, (q1, q2, values)) in enumerate(fields.items(), start=2):
        ax = fig.add_subplot(1, len(fields) + 1, k)
        top = float(np.max(np.abs(values)))
        ax.contourf(q1, q2, values, levels=30, cmap="RdBu_r", vmin=-top, vmax=top)
        ax.contour(q1, q2, values, levels=15, colors="k", linewidths=0.4, alpha=0.5)
        ax.contour(q1, q2, values, levels=[0.0], colors="k", linewidths=1.5)
        if path_q is not None:
            ax.plot(path_q[:, 0], path_q[:, 1], "g-", linewidth=2)
        ax.set_xlabel("q1 (rad)")
        ax.set_ylabel("q2 (rad)")
        ax.set_aspect("equal")
        ax.set_title(f"({chr(96 + k)}) {name}")
    fig.tight_layout()
    return fig


def roc_figure(curves: dict[str, dict[str, tuple[np.ndarray, np.ndarray, float]]]) -> Figure:
    """ROC curves, one panel per environment: ``curves[env][method] = (fpr, tpr, auc)``."""
    fig = Figure(figsize=(3.6 * len(curves), 3.6))
    for k, (env, methods) in enumerate(curves.items(), start=1):
        ax = fig.add_subplot(1, len(curves), k)
        for method, (fpr, tpr, auc) in methods.items():
            ax.plot(fpr, tpr, label=f"{method} ({auc:.4f})")
        ax.plot([0, 1], [0, 1], "k:", linewidth=0.8)
        ax.set_xlabel("false-positive rate")
        ax.set_ylabel("true-positive rate")
        ax.set_title(f"env {env}: collision (f ≤ 0)")
        ax.legend(fontsize=7, loc="lower right")
        ax.set_aspect("equal")
    fig.tight_layout()
    return fig


def scatter_figure(points: dict[str, dict[str, tuple[np.ndarray, np.ndarray]]]) -> Figure:
    """Predicted vs coal distance, one panel per environment: ``points[env][method] = (f, d̂)``."""
    fig = Figure(figsize=(3.6 * len(points), 3.6))
    for k, (env, methods) in enumerate(points.items(), start=1):
        ax = fig.add_subplot(1, len(points), k)
        lo, hi = np.inf, -np.inf
        for method, (true, pred) in methods.items():
            ax.scatter(true, pred, s=2, alpha=0.4, label=method)
            lo, hi = min(lo, true.min(), pred.min()), max(hi, true.max(), pred.max())
        ax.plot([lo, hi], [lo, hi], "k--", linewidth=0.8)
        ax.set_xlabel("coal f (m)")
        ax.set_ylabel("predicted d̂ (m)")
        ax.set_title(f"env {env}")
        ax.legend(fontsize=7, markerscale=4)
    fig.tight_layout()
    return fig


ABLATION_PANELS = (  # (score key, unit factor, axis label, log scale, over seeds)
    ("mae", 1e3, "MAE (mm)", True, "mean"),
    ("acd", 1.0, "ACD", False, "mean"),
    ("grad_time", 1e3, "d̂ + ∇ (ms / configuration)", True, "mean"),
    ("sweep_max", 1e2, "largest sweep step (cm)", True, "max"),
)


def ablation_figure(steps: list[str], results: dict[str, list[list[dict]]]) -> Figure:
    """The ablation's columns over its steps, one line per environment: MAE, ACD, d̂ + ∇ time
    and the largest d̂ step of the joint sweeps (``results[env][step]`` = the scores of each
    trained seed, :func:`gdnplan.ablation.run`). MAE, ACD and time: the mean over seeds ± its
    standard error (≥ 2 seeds); sweeps: the largest over seeds; untrained steps are gaps."""
    if any(len(per_step) != len(steps) for per_step in results.values()):
        raise InputError("results: expected one list of seed scores per step for every env")
    fig = Figure(figsize=(4.2 * len(ABLATION_PANELS), 4.2))
    x = np.arange(len(steps))
    for k, (key, unit, label, log, over) in enumerate(ABLATION_PANELS, start=1):
        ax = fig.add_subplot(1, len(ABLATION_PANELS), k)
        for env, per_step in results.items():
            values = [unit * np.array([r[key] for r in runs]) for runs in per_step]
            mid = [np.nan if not v.size else v.max() if over == "max" else v.mean() for v in values]
            se = [v.std(ddof=1) / np.sqrt(v.size) if v.size > 1 and over == "mean" else 0.0
                  for v in values]  # fmt: skip
            ax.errorbar(x, mid, yerr=se, marker="o", capsize=3, label=f"({env})")
        ax.set_xticks(x, steps, rotation=40, ha="right")
        ax.set_ylabel(label)
        if log:
            ax.set_yscale("log")
        ax.grid(alpha=0.3)
    fig.axes[0].legend()
    fig.tight_layout()
    return fig
