"""Padded batches of ring graphs: the tensors every graph of :mod:`gdnplan.graph` becomes.

A graph is a union of rings: node i is linked to its predecessor and successor on its polygon,
N(i) = {prev(i), next(i)}. :class:`GraphBatch` holds B such graphs padded to the largest, N
nodes: padded slots have ``mask = False`` and point to themselves. :func:`rings` compacts padded
polygons into that form without a loop over samples, :func:`densify_padded` splits the edges of
padded polygons first, :func:`collate` pads per-sample graphs of different robots.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import torch

from .errors import InputError


@dataclass(frozen=True)
class GraphBatch:
    """B ring graphs padded to N nodes.

    Attributes:
        nodes: (B, N, 2) node coordinates (m, or normalised units inside the model).
        prev: (B, N) long, index of the previous node on the same ring.
        next: (B, N) long, index of the next node on the same ring.
        mask: (B, N) bool, True for real nodes.
    """

    nodes: torch.Tensor
    prev: torch.Tensor
    next: torch.Tensor
    mask: torch.Tensor

    @classmethod
    def from_numpy(
        cls,
        nodes: np.ndarray,
        prev: np.ndarray,
        next: np.ndarray,
        mask: np.ndarray,
        device: str | torch.device = "cpu",
        dtype: torch.dtype = torch.float32,
    ) -> GraphBatch:
        return cls(
            torch.as_tensor(nodes, dtype=dtype, device=device),
            torch.as_tensor(prev, dtype=torch.long, device=device),
            torch.as_tensor(next, dtype=torch.long, device=device),
            torch.as_tensor(mask, dtype=torch.bool, device=device),
        )

    def __len__(self) -> int:
        return self.nodes.shape[0]

    def with_nodes(self, nodes: torch.Tensor) -> GraphBatch:
        """The same structure with other node coordinates (B, N, 2)."""
        return GraphBatch(nodes, self.prev, self.next, self.mask)

    def index(self, rows: torch.Tensor | slice) -> GraphBatch:
        """The graphs at ``rows``, trimmed to their largest node count."""
        mask = self.mask[rows]
        n = max(int(mask.sum(1).max()), 1) if mask.numel() else 1
        return GraphBatch(
            self.nodes[rows][:, :n], self.prev[rows][:, :n], self.next[rows][:, :n], mask[:, :n]
        )

    def to(self, device: str | torch.device) -> GraphBatch:
        return GraphBatch(*(t.to(device) for t in (self.nodes, self.prev, self.next, self.mask)))


def rings(
    points: np.ndarray, valid: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Compact padded polygons into padded ring graphs, without a loop over samples.

    Args:
        points: (B, P, S, 2) vertex slots of P polygons, in ring order along S.
        valid: (B, P, S) True for real vertices (any pattern; order along S is kept).

    Returns:
        nodes (B, N, 2), prev (B, N), next (B, N), mask (B, N) with N the largest node count.
    """
    b = valid.shape[0]
    count = valid.sum(-1)  # (B, P)
    pos = np.cumsum(valid, -1) - 1  # position of each slot within its ring
    offset = np.cumsum(count, -1) - count  # first node of each ring
    total = count.sum(-1)  # (B,)
    n = max(int(total.max(initial=0)), 1)
    idx = offset[..., None] + pos  # (B, P, S) compacted index of each slot
    cnt = np.maximum(count, 1)[..., None]
    bi = np.broadcast_to(np.arange(b)[:, None, None], valid.shape)[valid]
    slot = idx[valid]
    nodes = np.zeros((b, n, 2), dtype=points.dtype)
    nodes[bi, slot] = points[valid]
    prev = np.broadcast_to(np.arange(n), (b, n)).copy()
    next = prev.copy()
    prev[bi, slot] = (offset[..., None] + (pos - 1) % cnt)[valid]
    next[bi, slot] = (offset[..., None] + (pos + 1) % cnt)[valid]
    mask = np.arange(n) < total[:, None]
    return nodes, prev, next, mask


def densify_padded(
    polygons: np.ndarray, sizes: np.ndarray, max_edge: float | None
) -> tuple[np.ndarray, np.ndarray]:
    """Vertex slots and validity of padded polygons, edges split to at most ``max_edge`` (m).

    Edge v → v+1 of a polygon with m vertices is split into k = ⌈|e| / max_edge⌉ pieces with
    points a + (t/k)(b − a), t = 0 … k − 1 (the same points as :func:`geometry.densify`).

    Args:
        polygons: (B, P, V, 2) zero-padded CCW polygons.
        sizes: (B, P) vertex counts.
        max_edge: longest edge after splitting, or None to keep the vertices.

    Returns:
        points (B, P, S, 2) and valid (B, P, S), S = V · (most pieces of any edge).
    """
    v = polygons.shape[2]
    valid = np.arange(v) < sizes[..., None]  # (B, P, V)
    if max_edge is None:
        return polygons, valid
    if max_edge <= 0:
        raise InputError(f"max_edge: expected a positive length (m) or None, got {max_edge}")
    nxt = (np.arange(v) + 1) % np.maximum(sizes[..., None], 1)  # (B, P, V)
    b_vertex = np.take_along_axis(polygons, nxt[..., None], 2)
    length = np.linalg.norm(b_vertex - polygons, axis=-1)
    pieces = np.where(valid, np.maximum(np.ceil(length / max_edge), 1), 0).astype(int)
    k = max(int(pieces.max(initial=1)), 1)
    t = np.arange(k)  # (k,)
    frac = t / np.maximum(pieces, 1)[..., None]  # (B, P, V, k)
    pts = polygons[..., None, :] + frac[..., None] * (b_vertex - polygons)[..., None, :]
    ok = t < pieces[..., None]
    shape = (*polygons.shape[:2], v * k)
    return pts.reshape(*shape, 2), ok.reshape(shape)


def collate(graphs: list[tuple[np.ndarray, np.ndarray, np.ndarray]], **kwargs) -> GraphBatch:
    """Pad per-sample graphs (nodes (n_i, 2), prev (n_i,), next (n_i,)) into one GraphBatch.

    For robots whose graph changes between samples (e.g. the UR5e with different grippers).
    """
    if not graphs:
        raise InputError("graphs: expected at least one graph to collate")
    n = max(len(g[0]) for g in graphs)
    b = len(graphs)
    nodes = np.zeros((b, n, 2))
    prev = np.broadcast_to(np.arange(n), (b, n)).copy()
    next = prev.copy()
    mask = np.zeros((b, n), bool)
    for i, (x, p, nx) in enumerate(graphs):
        k = len(x)
        nodes[i, :k], prev[i, :k], next[i, :k], mask[i, :k] = x, p, nx, True
    return GraphBatch.from_numpy(nodes, prev, next, mask, **kwargs)


__all__ = [
    "GraphBatch",
    "collate",
    "densify_padded",
    "rings",
]
