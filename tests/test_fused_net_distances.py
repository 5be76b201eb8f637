"""The compiled ring distances of models/graphdistnet/fused_net_distances.py against shapely
(independent truth): random star-shaped (often non-convex) counter-clockwise rings, several per
scene and possibly overlapping, and points spread over and around them, some on their edges."""

import itertools
import os

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from shapely.geometry import Point, Polygon

from gdnplan.models.graphdistnet import fused as fused_kernel

pytestmark = pytest.mark.skipif(
    not fused_kernel.AVAILABLE and os.environ.get("CI") != "true", reason="numba not installed"
)


def star(rng: np.random.Generator) -> np.ndarray:
    """A counter-clockwise star-shaped ring of 3–9 vertices around a random centre."""
    n = int(rng.integers(3, 10))
    angles = np.sort(rng.uniform(0, 2 * np.pi, n))
    radii = rng.uniform(0.05, 0.6, n)
    centre = rng.uniform(-1, 1, 2)
    return centre + radii[:, None] * np.stack([np.cos(angles), np.sin(angles)], 1)


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), rings=st.integers(1, 4))
def test_ring_distances_match_shapely(seed, rings):
    from gdnplan.models.graphdistnet.fused_net_distances import _ring_distances

    rng = np.random.default_rng(seed)
    polys = [star(rng) for _ in range(rings)]
    nodes = np.concatenate(polys)
    sizes = np.cumsum([0] + [len(p) for p in polys])
    onext = np.concatenate([np.roll(np.arange(a, b), -1) for a, b in itertools.pairwise(sizes)])
    points = rng.uniform(-1.8, 1.8, (60, 2))
    on_edge = nodes + rng.uniform(0, 1, (len(nodes), 1)) * (nodes[onext] - nodes)
    points = np.concatenate([points, on_edge[:8]])
    s, gx, gy = (np.empty(len(points)) for _ in range(3))
    _ring_distances(
        points[:, 0].copy(), points[:, 1].copy(), nodes, onext.astype(np.int64), s, gx, gy
    )
    shapes = [Polygon(p) for p in polys]
    for x, got in zip(points, s, strict=True):
        pt = Point(x)
        edge = min(p.exterior.distance(pt) for p in shapes)  # the nearest ring edge, any ring
        inside = any(p.buffer(0).contains(pt) for p in shapes)
        assert abs(got) == pytest.approx(max(edge, 1e-6), abs=1e-9)  # δ floored at 1e-6, as torch's
        if edge > 1e-9:  # on an edge the sign is either
            assert (got < 0) == inside, (x, got)
    unit = np.hypot(gx, gy)  # ∇|δ| is a unit vector wherever δ > 0
    far = np.abs(s) > 1e-6
    np.testing.assert_allclose(unit[far], 1.0, atol=1e-9)
