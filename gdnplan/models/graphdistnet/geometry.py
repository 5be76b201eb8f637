"""Node geometry of GraphDistNet: nearest cross-graph candidates and signed ring distances
(normalised units; see the package docstring)."""

from __future__ import annotations

import math

import torch
from torch import nn

PAD_DIST2 = 1e6  # squared distance (normalised units²) given to padded candidates


def nearest_candidates(d2: torch.Tensor, c: int) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
    """The c nearest nodes of the other graph for every union node, robot nodes first.

    Args:
        d2: (B, N_r, N_o) squared distances between robot and obstacle nodes.
        c: candidates per node (capped at the larger graph's size).

    Returns:
        idx (B, N, C) union indices (obstacles shifted by N_r), log φ (B, N, C) with
        φ_c = d²_C − d²_c (−∞ on padding when the other graph has fewer than C nodes) and the
        candidates' d² (B, N, C), ascending.
    """
    n_r = d2.shape[1]
    c = min(c, max(d2.shape[1:]))
    out = []
    for dist, offset in ((d2, n_r), (d2.transpose(1, 2), 0)):
        idx, log_phi, near = nearest_columns(dist, c)
        out.append((idx + offset, log_phi, near))
    return tuple(torch.cat(parts, 1) for parts in zip(*out, strict=True))


def nearest_columns(dist: torch.Tensor, c: int) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
    """Column indices (B, n, c), log φ (B, n, c) and values (B, n, c) of the c smallest entries of
    every row of ``dist`` (B, n, m), ascending; padded with zero-weight (log φ = −∞) candidates
    when m < c. φ_c = d²_c_max − d²_c as in :func:`nearest_candidates`."""
    kk = min(c, dist.shape[-1])
    near, idx = torch.topk(dist, kk, dim=-1, largest=False)  # ascending
    log_phi = (near[..., -1:] - near).clamp_min(1e-12).log()
    if kk < c:  # a small other graph: pad with zero-weight candidates
        pad = (0, c - kk)
        near = nn.functional.pad(near, pad, value=PAD_DIST2)
        log_phi = nn.functional.pad(log_phi, pad, value=-math.inf)
        idx = nn.functional.pad(idx, pad)
    return idx, log_phi, near


def nearest_obstacle_nodes(
    xr: torch.Tensor, xo: torch.Tensor, c: int
) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
    """:func:`nearest_columns` of the robot–obstacle squared distances, c ≤ N_o, with a sparse
    gradient.

    The c nearest obstacle nodes are chosen on the dense (B, N_r, N_o) distances without
    autograd; their d²_c = |x_r − x_o,c|² are then recomputed from the (B, N_r, c, 2) differences
    (the same floating-point operations, so the same values): the backward pass touches c
    candidates per robot node instead of all N_o obstacle nodes.

    Args:
        xr: (B, N_r, 2) robot nodes; xo: (N_o, 2) obstacle nodes (normalised units).
    """
    with torch.no_grad():
        idx = torch.topk(_pairwise_d2(xr, xo), c, dim=-1, largest=False).indices  # ascending
    diff = xr[..., None, :] - xo[idx]
    near = (diff * diff).sum(-1)
    return idx, (near[..., -1:] - near).clamp_min(1e-12).log(), near


def _pairwise_d2(xr: torch.Tensor, xo: torch.Tensor) -> torch.Tensor:
    """(B, N_r, N_o) squared distances between robot nodes xr (B, N_r, 2) and obstacle nodes
    xo (N_o, 2): (x_r − x_o)² + (y_r − y_o)², the same floating-point operations as summing
    the squared differences over the last axis, in half the memory passes."""
    dx = xr[..., 0, None] - xo[:, 0]
    dy = xr[..., 1, None] - xo[:, 1]
    return dx * dx + dy * dy


def signed_ring_distance(
    points: torch.Tensor, nodes: torch.Tensor, next: torch.Tensor, mask: torch.Tensor | None = None
) -> torch.Tensor:
    """Signed distance (B, P) of points (B, P, 2) to the union of counter-clockwise rings.

    Rings: nodes (B, M, 2) (or (1, M, 2), shared), next (B, M) and mask (B, M) (None: every
    node is real); edge m runs from a_m to b_m = a_next(m). The distance is to the nearest edge,

        δ_pm = |p − a_m − t e_m|,  e_m = b_m − a_m,  t = clamp((p − a_m)·e_m / |e_m|², 0, 1),

    s_p = ± min_m δ_pm, negative where p is inside a ring (non-zero winding number: edges
    crossing the ray p + λ x̂, λ > 0, counted +1 upwards with p on their left, −1 downwards
    with p on their right; an edge crosses when a_y ≤ p_y < b_y or b_y ≤ p_y < a_y, the
    coordinates compared as they are, so that two edges sharing a vertex agree on which side
    of it p lies even when p_y is within rounding of the vertex's). s is continuous in p and
    in the nodes (the sign switches where min δ = 0); masked edges are left out. Between two
    apart polygons the distance is the smallest |s| over the vertices of both, since a closest
    pair has a vertex at one end.

    The nearest edge and the winding number are found without autograd over all (P, M)
    pairs; δ is then recomputed, differentiably, for the nearest edge only (the gradient of
    a minimum is its minimiser's), so the backward pass costs O(B P), not O(B P M).
    """
    b = points.shape[0]
    ends = torch.gather(nodes, 1, next[..., None].expand(*next.shape, 2))
    edges = ends - nodes  # (B or 1, M, 2)
    edge_mask = None if mask is None else mask[:, None]
    d2_min, nearest, inside = _nearest_edge_and_inside(
        points.detach(), nodes[:, None].detach(), edges[:, None].detach(), edge_mask,
        ends[:, None, :, 1].detach(),
    )  # fmt: skip
    pick = nearest[..., None].expand(*nearest.shape, 2)
    a = torch.gather(nodes.expand(b, -1, -1), 1, pick)  # (B, P, 2)
    e = torch.gather(edges.expand(b, -1, -1), 1, pick)
    w = points - a
    t = ((w * e).sum(-1) / (e * e).sum(-1).clamp_min(1e-12)).clamp(0.0, 1.0)
    dist = (w - t[..., None] * e).square().sum(-1).clamp_min(1e-12).sqrt()
    dist = torch.where(d2_min < PAD_DIST2, dist, math.sqrt(PAD_DIST2))  # every edge masked
    return torch.where(inside, -dist, dist)


@torch.no_grad()
def _nearest_edge_and_inside(
    points: torch.Tensor,
    a: torch.Tensor,
    e: torch.Tensor,
    mask: torch.Tensor | None,
    end_y: torch.Tensor,
) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
    """For points (B, P, 2) and edges a_m + t e_m given by a and e (B or 1, P or 1, M, 2),
    ending at height end_y = b_y (B or 1, P or 1, M), masked edges (mask broadcastable to
    (B, P, M)) left out: the smallest squared distance min_m δ²_pm (B, P), its edge m (B, P),
    and whether the winding number around p is non-zero (B, P) (see
    :func:`signed_ring_distance`).

    x and y are separate contiguous (B, P, M) tensors (no reductions over a trailing 2)."""
    ax, ay = a[..., 0].contiguous(), a[..., 1].contiguous()
    ex, ey = e[..., 0].contiguous(), e[..., 1].contiguous()
    wx = points[..., 0, None] - ax  # (B, P, M)
    wy = points[..., 1, None] - ay
    inv = (ex * ex + ey * ey).clamp_min_(1e-12).reciprocal_()
    t = (wx * ex).add_(wy * ey).mul_(inv).clamp_(0.0, 1.0)
    d2 = (wx - t * ex).square_().add_((wy - t * ey).square_())
    if mask is not None:
        d2 = d2.masked_fill_(~mask, PAD_DIST2)
    d2_min, nearest = d2.min(-1)
    left = (ex * wy).sub_(ey * wx)  # e × (p − a) > 0: p left of the edge
    py = points[..., 1, None]
    up = (ay <= py) & (py < end_y)  # a_y ≤ p_y < b_y (coordinates, not their differences)
    down = (end_y <= py) & (py < ay)  # b_y ≤ p_y < a_y
    winding = (up & (left > 0)).int() - (down & (left < 0)).int()
    if mask is not None:
        winding = winding.masked_fill(~mask, 0)
    return d2_min, nearest, winding.sum(-1) != 0
