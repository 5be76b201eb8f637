"""The straight line ends exactly at its goal: start + 1 · (goal − start) was an ulp off it
for 8 % of random pairs, so a plan whose straight line was certified ended beside its goal, and
the 3-D fetch, which stacks its pieces on the promise that each ends where the next begins,
joined them by a segment that no certificate had seen."""

from __future__ import annotations

import numpy as np
from hypothesis import example, given, settings
from hypothesis import strategies as st

import gdnplan as gp
from gdnplan.trajopt import Problem, plan, straight_line

angles = st.lists(st.floats(-10.0, 10.0), min_size=2, max_size=2)


@settings(max_examples=200, deadline=None)
@given(a=angles, b=angles, n=st.integers(2, 50))
@example(a=[-2.1, 0.0], b=[1.3, 0.0], n=5)  # −2.1 + 1 · 3.4 = 1.3000000000000003
def test_a_straight_line_begins_and_ends_exactly_at_its_ends(a, b, n):
    line = straight_line(np.array(a), np.array(b), n)
    assert line.shape == (n, 2)
    assert np.array_equal(line[0], a) and np.array_equal(line[-1], b)


def test_a_plan_on_its_certified_straight_line_ends_exactly_at_the_goal():
    scene = gp.make_scene("a").with_obstacles([])
    p = Problem(scene=scene, start=[-2.1, 0.0], goal=[1.3, 0.0], waypoints=5, margin=0.02)
    result = plan(p, collision="coal")
    assert result.success and result.seed.kind == "straight", result.reason
    assert np.array_equal(result.q[-1], [1.3, 0.0])
