"""The 3-D fetch stages: one planned stage end to end (fast), the scripted grasp and lift, the
pieces of a stage, and (slow) all six stages certified on 8 random storage placements."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from gdnplan.arm3d import certify_path3d, checker3d
from gdnplan.arm3d.fetch3d import PLANNED, STAGES, knots, run_fetch3d, stage_problems
from gdnplan.arm3d.fetch3d_scene import fetch3d
from gdnplan.errors import InputError


@pytest.fixture(scope="module")
def canonical():
    return fetch3d(0)


def test_the_approach_is_planned_and_its_path_certified(canonical):
    (stage,) = run_fetch3d(fetch=canonical, stages=("approach",))
    assert stage.planned and stage.success and stage.gripper == "open"
    assert np.allclose(stage.q[0], canonical.q["q_home"])
    assert np.allclose(stage.q[-1], canonical.q["q_pregrasp"])
    cert = certify_path3d(canonical.scenes["open"], stage.q, margin=0.01)  # independently
    assert cert.ok and stage.min_distance > 0.01


def test_grasp_and_lift_are_scripted_and_certified(canonical):
    grasp, lift = run_fetch3d(fetch=canonical, stages=("grasp", "lift"))
    assert grasp.success and not grasp.planned and abs(grasp.min_distance) < 1e-6
    assert lift.success and abs(lift.min_distance) <= 1e-9  # it starts resting on the shelf
    assert lift.certified_from == 1 and lift.certified_min_distance > 0
    assert "first segment proven never to penetrate by 10 µm" in lift.detail  # not sampled
    assert np.allclose(lift.q[0], canonical.q["q_grasp"])
    assert np.allclose(lift.q[-1], canonical.q["q_lift"])


def test_the_lifts_min_distance_is_the_minimum_over_its_whole_path(canonical):
    """min_distance means what it says: coal's minimum along all of q (0: the stick rests on
    its shelf at q[0]); the certified part and its proven bound are reported apart."""
    (lift,) = run_fetch3d(fetch=canonical, stages=("lift",))
    scene = lift.scene
    s = np.linspace(0.0, 1.0, 40)[:, None]
    dense = np.vstack([a + s * (b - a) for a, b in itertools.pairwise(lift.q)])
    coal = checker3d(scene).evaluate(dense).distance
    assert lift.min_distance == pytest.approx(coal.min(), abs=1e-9)
    assert certify_path3d(scene, lift.q[lift.certified_from :], 0.0).lower_bound == pytest.approx(
        lift.certified_min_distance
    )
    summary = lift.summary()
    assert summary["min_distance"] == pytest.approx(coal.min(), abs=1e-9)
    assert summary["certified_from"] == 1
    assert summary["certified_min_distance"] == lift.certified_min_distance
    assert coal[40:].min() >= lift.certified_min_distance  # the bound holds where it is claimed


def test_stages_along_tool_lines_are_planned_in_pieces_between_knots(canonical):
    for name in PLANNED:
        problems = stage_problems(canonical, name)
        points = knots(canonical, name)
        assert len(problems) == len(points) - 1
        start, goal = PLANNED[name][1:]
        assert np.allclose(problems[0].start, canonical.q[start])
        assert np.allclose(problems[-1].goal, canonical.q[goal])
        for a, b in itertools.pairwise(problems):
            assert np.array_equal(a.goal, b.start)
        expect = "holding" if name in ("bring_out", "retreat") else "open"
        assert all(p.scene is canonical.scenes[expect] for p in problems)
    assert len(stage_problems(canonical, "bring_out")) > 1


def test_unknown_stages_are_input_errors(canonical):
    with pytest.raises(InputError, match="stages"):
        run_fetch3d(fetch=canonical, stages=("jump",))
    with pytest.raises(InputError, match="not planned"):
        stage_problems(canonical, "grasp")


@pytest.mark.slow
@pytest.mark.parametrize("seed", range(1, 9))
def test_every_stage_is_certified_on_eight_random_placements(seed):
    stages = run_fetch3d(seed)
    assert [s.name for s in stages] == list(STAGES)
    failed = [(s.name, s.detail) for s in stages if not s.success]
    assert not failed
    for s in stages:
        if s.planned:  # re-certified here, independently of the planner's verdict
            assert certify_path3d(s.scene, s.q, margin=0.01).ok, s.name
