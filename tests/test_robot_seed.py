"""Robot.sample's seeds: integers, lists, None and a numpy Generator (whose stream continues,
as np.random.default_rng(generator) always did); anything else is an InputError."""

import numpy as np
import pytest

import gdnplan as gp
from gdnplan.errors import InputError
from gdnplan.robot import make_rng


@pytest.fixture(scope="module")
def robot():
    return gp.make_scene("a").robot


def test_generator_seed_continues_its_stream(robot):
    rng = np.random.default_rng(11)
    rng.normal(size=3)
    got = robot.sample(5, seed=rng)
    ref = np.random.default_rng(11)
    ref.normal(size=3)
    np.testing.assert_array_equal(got, ref.uniform(robot.lower, robot.upper, (5, robot.dof)))
    # the caller's generator advanced by the draw, exactly as before
    assert rng.random() == ref.random()


@pytest.mark.parametrize("seed", [0, 7, [3, 4], np.int64(9)])
def test_integer_seeds_unchanged(robot, seed):
    ref = np.random.default_rng(seed).uniform(robot.lower, robot.upper, (4, robot.dof))
    np.testing.assert_array_equal(robot.sample(4, seed=seed), ref)


@pytest.mark.parametrize("seed", [-1, True, 1.5, "3", [], [1, -2], np.random.RandomState(0)])
def test_bad_seeds_refused(robot, seed):
    with pytest.raises(InputError, match="seed"):
        robot.sample(3, seed=seed)


def test_make_rng_returns_the_generator_itself():
    rng = np.random.default_rng(0)
    assert make_rng(rng) is rng
    with pytest.raises(InputError, match="stream"):
        make_rng(-3, "stream")
