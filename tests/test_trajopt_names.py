"""The public names of gdnplan.trajopt: the deprecated alias solve_ik of numeric_ik."""

import warnings

import numpy as np
import pytest

import gdnplan as gp
from gdnplan import trajopt
from gdnplan.trajopt import Problem, numeric_ik, tip_position


def test_solve_ik_is_a_deprecated_alias_of_numeric_ik():
    scene = gp.make_scene("a")
    start, goal = np.array([1.3, -2.9]), np.array([1.5, 0.1])
    target = tip_position(scene.robot, goal)[0]
    problem = Problem(scene=scene, start=start, goal_position=target, waypoints=10)
    with pytest.warns(DeprecationWarning, match=r"gdnplan\.trajopt\.numeric_ik") as record:
        from gdnplan.trajopt import solve_ik
    assert "gdnplan.ur5e.analytic_ik" in str(record[0].message)
    assert solve_ik is numeric_ik
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # the new name does not warn
        q = numeric_ik(problem, seed=3)
    assert np.array_equal(solve_ik(problem, seed=3), q)
    assert np.linalg.norm(tip_position(scene.robot, q)[0] - target) <= problem.goal_tolerance


def test_unknown_names_still_raise_attribute_error():
    with pytest.raises(AttributeError, match="no attribute 'bogus'"):
        trajopt.bogus  # noqa: B018
    with pytest.raises(ImportError):
        from gdnplan.trajopt import bogus  # noqa: F401
    assert "solve_ik" not in trajopt.__all__
