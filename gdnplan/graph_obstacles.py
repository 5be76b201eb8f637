"""Obstacle graphs (paper §IV-A): the rings of a batch of obstacle sets, padded.

The obstacle graph of a scene holds its (possibly non-convex) obstacle polygons as rings
(:mod:`gdnplan.graph_batch`), nodes at the vertices (m), edges longer than ``max_edge``
split by extra nodes.
"""

from __future__ import annotations

import numpy as np
import torch

from .errors import InputError
from .graph_batch import GraphBatch, densify_padded, rings
from .scene import Scene


def obstacle_graph(
    polygons: np.ndarray,
    sizes: np.ndarray,
    max_edge: float | None = None,
    device: str | torch.device = "cpu",
    dtype: torch.dtype = torch.float32,
) -> GraphBatch:
    """Obstacle graphs of a batch of obstacle sets.

    Args:
        polygons: (B, P, V, 2) zero-padded CCW polygons (m), as stored by :mod:`gdnplan.data`.
        sizes: (B, P) vertex counts (0 = no polygon in this slot).
        max_edge: densify edges longer than this (m), or None.

    Returns:
        GraphBatch with the union of the rings of each sample's polygons.
    """
    polygons = np.asarray(polygons, dtype=float)
    sizes = np.asarray(sizes)
    if polygons.ndim != 4 or polygons.shape[-1] != 2 or sizes.shape != polygons.shape[:2]:
        raise InputError(
            f"obstacles: expected polygons (B, P, V, 2) and sizes (B, P), got "
            f"{polygons.shape} and {sizes.shape}"
        )
    if np.any(sizes > polygons.shape[2]) or np.any((sizes > 0) & (sizes < 3)):
        raise InputError("obstacles sizes: each polygon needs 3 … V vertices (or 0 for none)")
    if not np.all(np.isfinite(polygons)):
        raise InputError("obstacles: contains NaN or infinite coordinates")
    points, valid = densify_padded(polygons, sizes, max_edge)
    return GraphBatch.from_numpy(*rings(points, valid), device=device, dtype=dtype)


def scene_obstacles(scenes: list[Scene]) -> tuple[np.ndarray, np.ndarray]:
    """Padded obstacle polygons (B, P, V, 2) and sizes (B, P) of a list of scenes."""
    if not scenes or any(len(s.obstacles) == 0 for s in scenes):
        raise InputError("scene.obstacles: GraphDistNet needs at least one obstacle polygon")
    n_poly = max(len(s.obstacles) for s in scenes)
    n_vert = max(len(p) for s in scenes for p in s.obstacles)
    out = np.zeros((len(scenes), n_poly, n_vert, 2))
    sizes = np.zeros((len(scenes), n_poly), np.int64)
    for i, s in enumerate(scenes):
        for j, p in enumerate(s.obstacles):
            out[i, j, : len(p)] = p
            sizes[i, j] = len(p)
    return out, sizes


__all__ = [
    "obstacle_graph",
    "scene_obstacles",
]
