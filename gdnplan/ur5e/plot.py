"""A PNG of a fetch scene with the robot at one configuration (matplotlib)."""

from __future__ import annotations

import numpy as np

from ..distance import signed_distance
from ..files import atomic_path
from ..scene import Scene


def plot_fetch(scene: Scene, q: np.ndarray, path: str) -> None:
    """Save a PNG of the scene with the robot at q (3,): obstacles grey, links coloured."""
    import matplotlib.pyplot as plt
    from matplotlib.patches import Polygon as Patch

    fig, ax = plt.subplots(figsize=(8, 5.5))
    stick = scene.info.get("stick")
    for poly in scene.obstacles:
        is_stick = stick is not None and poly.shape == stick.shape and np.allclose(poly, stick)
        ax.add_patch(Patch(poly, facecolor="goldenrod" if is_stick else "0.75", edgecolor="0.3"))
    colors = ["tab:blue", "tab:orange", "tab:green", "tab:red", "tab:purple", "tab:brown"]
    colors += ["tab:pink", "tab:olive", "tab:cyan"]
    links = scene.robot.polygons
    for i, (link, poly) in enumerate(zip(links, scene.robot.link_polygons(q), strict=True)):
        ax.add_patch(Patch(poly, alpha=0.6, facecolor=colors[i % len(colors)], label=link.name))
    d = float(signed_distance(scene, q)[0])
    ax.set_title(
        f"{scene.name} seed {scene.seed}, gripper {scene.robot.info['gripper']}: "
        f"q = {np.round(q, 3).tolist()}, clearance {d * 1000:.1f} mm"
    )
    ax.set(xlim=(-0.4, 1.3), ylim=(-0.3, 0.9), aspect="equal", xlabel="u (m)", ylabel="v (m)")
    ax.legend(loc="upper right", fontsize=7)
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=110, bbox_inches="tight")
    plt.close(fig)
