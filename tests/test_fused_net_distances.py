"""The ring distances (models/graphdistnet/fused_net_distances.py, compiled, and
geometry.signed_ring_distance, torch) against shapely (independent truth): random
star-shaped (often non-convex) counter-clockwise rings, several per scene and possibly
overlapping, and points spread over and around them, some on their edges and some level with
their vertices (where a winding test on coordinate differences rounds two edges sharing the
vertex differently: a point outside read as inside), in float64 and float32."""

import itertools
import os

import numpy as np
import pytest
import torch
from hypothesis import given, settings
from hypothesis import strategies as st
from shapely.geometry import Point, Polygon

from gdnplan.models.graphdistnet import fused as fused_kernel
from gdnplan.models.graphdistnet.geometry import signed_ring_distance

needs_numba = pytest.mark.skipif(
    not fused_kernel.AVAILABLE and os.environ.get("CI") != "true", reason="numba not installed"
)


def star(rng: np.random.Generator) -> np.ndarray:
    """A counter-clockwise star-shaped ring of 3–9 vertices around a random centre; some
    vertices share a height with the one before (horizontal edges, as boxes have)."""
    n = int(rng.integers(3, 10))
    angles = np.sort(rng.uniform(0, 2 * np.pi, n))
    radii = rng.uniform(0.05, 0.6, n)
    centre = rng.uniform(-1, 1, 2)
    ring = centre + radii[:, None] * np.stack([np.cos(angles), np.sin(angles)], 1)
    level = rng.uniform(size=n) < 0.3
    ring[1:, 1] = np.where(level[1:], ring[:-1, 1], ring[1:, 1])
    if not Polygon(ring).is_valid:
        return centre + 0.3 * np.array([[0, -1], [1, 1], [-1, 1]])
    # levelling can turn a triangle clockwise; scenes hold CCW rings (geometry.as_polygon)
    return ring if Polygon(ring).exterior.is_ccw else ring[::-1].copy()


def scene(seed: int, rings: int, dtype) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(nodes (M, 2), next (M,), points (P, 2)) of ``dtype``: random points, points on edges,
    points level with vertices."""
    rng = np.random.default_rng(seed)
    polys = [star(rng) for _ in range(rings)]
    nodes = np.concatenate(polys).astype(dtype)
    sizes = np.cumsum([0] + [len(p) for p in polys])
    onext = np.concatenate([np.roll(np.arange(a, b), -1) for a, b in itertools.pairwise(sizes)])
    spread = rng.uniform(-1.8, 1.8, (60, 2))
    on_edge = nodes + rng.uniform(0, 1, (len(nodes), 1)) * (nodes[onext] - nodes)
    ulps = rng.integers(-3, 4, len(nodes))  # a vertex's height, or a few ulps off it
    heights = nodes[:, 1] + ulps * np.spacing(np.abs(nodes[:, 1])).astype(dtype)
    level = np.stack([rng.uniform(-1.8, 1.8, len(nodes)).astype(dtype), heights], 1)
    points = np.concatenate([spread.astype(dtype), on_edge[:8], level]).astype(dtype)
    return nodes, onext.astype(np.int64), points


def truth(nodes: np.ndarray, onext: np.ndarray, points: np.ndarray) -> tuple[np.ndarray, ...]:
    """(distance to the nearest ring edge, inside any ring) by shapely, in float64."""
    rings, start = [], 0
    for i in range(len(nodes)):
        if onext[i] < i:  # the ring closes here
            rings.append(Polygon(nodes[start : i + 1].astype(float)))
            start = i + 1
    edge = np.array([min(r.exterior.distance(Point(p)) for r in rings) for p in points])
    inside = np.array([any(r.contains(Point(p)) for r in rings) for p in points])
    return edge, inside


@needs_numba
@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), rings=st.integers(1, 4), single=st.booleans())
def test_compiled_ring_distances_match_shapely(seed, rings, single):
    from gdnplan.models.graphdistnet.fused_net_distances import _ring_distances

    dtype = np.float32 if single else np.float64
    nodes, onext, points = scene(seed, rings, dtype)
    s, gx, gy = (np.empty(len(points), dtype) for _ in range(3))
    _ring_distances(points[:, 0].copy(), points[:, 1].copy(), nodes, onext, s, gx, gy)
    edge, inside = truth(nodes, onext, points)
    tol = 1e-5 if single else 1e-9
    np.testing.assert_allclose(np.abs(s), np.maximum(edge, 1e-6), atol=tol)  # δ floored at 1e-6
    apart = edge > 10 * tol  # on an edge the sign is either
    np.testing.assert_array_equal((s < 0)[apart], inside[apart])
    far = np.abs(s) > 1e-4  # ∇|δ| is a unit vector wherever δ > 0
    np.testing.assert_allclose(np.hypot(gx, gy)[far], 1.0, atol=10 * tol)


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), rings=st.integers(1, 4), single=st.booleans())
def test_torch_ring_distances_match_shapely(seed, rings, single):
    dtype = np.float32 if single else np.float64
    nodes, onext, points = scene(seed, rings, dtype)
    s = signed_ring_distance(
        torch.from_numpy(points)[None], torch.from_numpy(nodes)[None], torch.from_numpy(onext)[None]
    )[0].numpy()
    edge, inside = truth(nodes, onext, points)
    tol = 1e-5 if single else 1e-9
    np.testing.assert_allclose(np.abs(s), np.maximum(edge, 1e-6), atol=tol)
    apart = edge > 10 * tol
    np.testing.assert_array_equal((s < 0)[apart], inside[apart])
