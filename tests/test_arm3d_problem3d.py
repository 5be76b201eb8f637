"""Random 3-D reaching problems: feasible ends, a colliding straight line, deterministic."""

import math

import numpy as np

from gdnplan.arm3d import checker3d, signed_distance3d
from gdnplan.arm3d.problem3d import collision_fraction, reaching_problems, reaching_scene


def test_reaching_problems_have_clear_ends_and_a_colliding_line():
    problems = reaching_problems("ur5e", 2, seed=5)
    for p in problems:
        ends = np.stack([p.start, p.goal])
        clear = checker3d(p.scene).evaluate(ends, contact_offset=p.margin).distance
        assert np.all(clear > p.margin)  # contact-only self pairs: d > 0 (offset = margin)
        assert np.all(signed_distance3d(p.scene, ends) > 0)
        line = p.start + np.linspace(0, 1, 50)[:, None] * (p.goal - p.start)
        assert np.min(signed_distance3d(p.scene, line)) <= 0
        assert np.all(p.lower >= -math.pi) and np.all(p.upper <= math.pi)
        assert np.all((p.start >= p.lower) & (p.start <= p.upper))
    again = reaching_problems("ur5e", 2, seed=5)
    for a, b in zip(problems, again, strict=True):
        np.testing.assert_array_equal(a.start, b.start)
        np.testing.assert_array_equal(a.goal, b.goal)


def test_collision_fraction_counts_colliding_configurations():
    scene = reaching_scene("ur5e", 0)
    share = collision_fraction(scene, 100, seed=1)
    q = scene.robot.random_configurations(100, np.random.default_rng(1))
    assert share == np.mean(signed_distance3d(scene, q) <= 0)
    assert 0.1 < share < 0.7
