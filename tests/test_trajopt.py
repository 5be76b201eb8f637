from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

import gdnplan as gp
from gdnplan import trajopt
from gdnplan.ccd import certify_path, lever_arms, motion_bound, verify_path
from gdnplan.models import CoalModel
from gdnplan.trajopt import (
    AdamConfig,
    IpoptConfig,
    Plan,
    PlanConfig,
    Problem,
    RefineConfig,
    SeedConfig,
    TrajoptOptions,
    _path_parameters,
    _Transcription,
    distance_bounds,
    plan,
    straight_line,
    tip_position,
)

START, GOAL = [1.3, -2.9], [1.5, 0.1]  # planar2 around env a's square; the straight line hits it


@pytest.fixture(scope="module")
def square():
    return gp.make_scene("a")


# the seeds' solves alone, without the polish and repair solves after them (gdnplan.trajopt.polish)
SEEDS_ONLY = {"polish": False, "repair": False}


def test_straight_line_of_the_test_problem_collides(square):
    ok, dmin = verify_path(square, straight_line(np.array(START), np.array(GOAL), 10))
    assert not ok and dmin < 0


def test_ipopt_solves_planar2_around_a_square_with_coal(square):
    p = Problem(scene=square, start=START, goal=GOAL, waypoints=10)
    result = plan(p, collision="coal")
    assert isinstance(result, Plan)
    assert result.success, result.reason
    assert result.iterations > 0 and result.model_calls > 0
    assert result.q.shape == (10, 2)
    np.testing.assert_allclose(result.q[[0, -1]], [START, GOAL])
    ok, dmin = verify_path(square, result.q)  # at margin 0: another bisection, within 1 mm
    assert ok and dmin > 0 and result.min_distance == pytest.approx(dmin, abs=1e-3)
    same = verify_path(square, result.q, margin=p.certified_clearance)  # the plan's certificate
    assert same[0] and result.min_distance == pytest.approx(same[1])


def test_extra_ipopt_options_reach_the_solver(square):
    p = Problem(scene=square, start=START, goal=GOAL, waypoints=10)
    cfg = PlanConfig(
        SeedConfig(starts=1, count=1),
        RefineConfig(ccd=False, polish=False),
        IpoptConfig(options={"max_iter": 2}),
    )
    result = plan(p, collision="coal", solver=cfg)
    assert result.iterations == 2 and result.status == "Maximum_Iterations_Exceeded"


def test_refine_round_warm_start_keeps_the_multipliers_of_kept_check_points(square):
    p = Problem(scene=square, start=START, goal=GOAL, waypoints=6)
    splits, refined = np.array([2, 2, 2, 2, 2]), np.array([2, 4, 2, 2, 2])
    np.testing.assert_array_equal(_path_parameters(splits)[:4], [0, 0.5, 1, 1.5])
    opts = IpoptConfig(per_link=False)
    nlp = _Transcription(p, CoalModel(), np.array(GOAL), opts, splits, p.margin)
    q, _ = nlp.solve(straight_line(np.array(START), np.array(GOAL), 6))
    lam_g, lam_x = nlp.duals_on(refined)
    warm = _Transcription(p, CoalModel(), np.array(GOAL), opts, refined, p.margin, warm=True)
    assert lam_g.shape == warm.lbg.shape and lam_x.shape == warm.lbx.shape
    old_g = nlp.duals[0]
    # inner check points: old 1 … 9 at s = 0.5 … 4.5; new: 0.5, 1, 1.25, 1.5, 1.75, 2, …
    np.testing.assert_array_equal(lam_g[:2], old_g[:2])  # s = 0.5, 1
    assert lam_g[2] == 0 and lam_g[4] == 0  # s = 1.25, 1.75: new
    np.testing.assert_array_equal(lam_g[[3, 5]], old_g[[2, 3]])  # s = 1.5, 2
    np.testing.assert_array_equal(lam_g[11:], old_g[9:])  # step rows
    assert np.abs(old_g).max() > 0  # the straight line hits the square: active rows
    _, stats = warm.solve(q, (lam_g, lam_x))
    assert stats["return_status"] in ("Solve_Succeeded", "Solved_To_Acceptable_Level")


def test_certified_check_rejects_a_path_clipping_a_corner(square):
    # both waypoints are free; the straight motion between them sweeps the arm through the square
    path = np.array([[0.2, 0.0], [1.2, 0.0]])
    assert np.all(gp.signed_distance(square, path) > 0.1)
    ok, dmin = verify_path(square, path)
    assert not ok and dmin < 0


def test_certificate_is_exact_on_a_free_segment_and_bounds_motion(square):
    robot = square.robot
    q = robot.sample(50, seed=3)
    dq = 1e-3 * np.ones((50, robot.dof))
    moved = np.linalg.norm(robot.node_positions(q + dq) - robot.node_positions(q), axis=-1).max(1)
    assert np.all(moved <= motion_bound(robot, q, q + dq) + 1e-12)
    assert lever_arms(robot).shape == (robot.n_links, robot.dof)
    cert = certify_path(square, np.array([[-1.0, 0.0], [-2.0, 0.5]]))
    assert cert.ok and cert.lower_bound > 0 and cert.bad_segments == ()


def test_goal_as_end_effector_position(square):
    target = tip_position(square.robot, np.array(GOAL))[0]
    p = Problem(scene=square, start=START, goal_position=target, waypoints=10)
    result = plan(p)
    assert result.success, result.reason
    assert np.linalg.norm(tip_position(square.robot, result.q[-1])[0] - target) <= 1e-3


def test_solver_failure_returns_unsuccessful_plan_with_reason(square):
    p = Problem(scene=square, start=START, goal=GOAL, waypoints=10)
    opts = PlanConfig(
        SeedConfig(initial="straight", starts=1), RefineConfig(ccd=False), IpoptConfig(max_iter=1)
    )
    result = plan(p, solver=opts)
    assert not result.success
    assert "Maximum_Iterations_Exceeded" in result.reason and "not certified" in result.reason


def test_adam_pushes_the_straight_line_out_of_the_square(square):
    p = Problem(scene=square, start=START, goal=GOAL, waypoints=20)
    result = plan(p, solver=AdamConfig())
    assert result.success, result.reason
    assert result.status == "adam: cost below threshold" and result.iterations > 1


@pytest.mark.parametrize(
    "config", [AdamConfig(c=1e300, eps=5e-324), AdamConfig(lr=1e308, c=1e300)], ids=["c/ε", "lr"]
)
def test_adam_stops_on_a_non_finite_step(square, config):
    """An overflowing collision cost made a NaN path, which the distance call refused as bad
    input ("q: contains NaN") though the caller gave no q: now a failed plan of finite q."""
    p = Problem(scene=square, start=START, goal=GOAL, waypoints=20)
    result = plan(p, solver=config)
    assert result.status.startswith("adam: diverged (a non-finite step; lower lr or c")
    assert np.all(np.isfinite(result.q)) and not result.success


class _Shaped:
    """A caller's model returning ``out(q)`` for the distances and gradients."""

    name = "shaped"

    def __init__(self, out):
        self.out = out

    def distance(self, scene, q):
        return self.out(q)[0]

    def distance_and_grad(self, scene, q):
        return self.out(q)


@pytest.mark.parametrize(
    ("out", "what"),
    [
        (lambda q: (np.zeros(3), np.zeros((3, 3))), r"distance returned .* shape \(3,\)"),
        (lambda q: (np.zeros(len(q)) + 1j, np.zeros(q.shape)), "distance returned .*complex"),
        (lambda q: (["0.1"] * len(q), np.zeros(q.shape)), "distance returned .*<U3"),
        (lambda q: (np.zeros(len(q)), np.zeros(len(q))), "gradients returned .* shape \\(2,\\)"),
    ],
    ids=["wrong length", "complex", "strings", "flat gradient"],
)
def test_a_callers_model_of_the_wrong_outputs_is_named_before_the_solver(square, out, what):
    """numpy raised its broadcast or ufunc error deep inside the solver (ipopt.py), a complex
    model lost its imaginary part silently."""
    p = Problem(scene=square, start=START, goal=GOAL, waypoints=10)
    with pytest.raises(gp.InputError, match=rf"^collision: model 'shaped': .*{what}"):
        plan(p, collision=_Shaped(out))


class Underestimating:
    """A learned stand-in: coal's distance minus 0.25 m (rates the whole problem too close)."""

    name = "underestimating"

    def distance(self, scene, q):
        return gp.signed_distance(scene, q) - 0.25

    def distance_and_grad(self, scene, q):
        d, g = gp.signed_distance_and_grad(scene, q)
        return d - 0.25, g


def test_distance_bounds_relax_only_the_end_segments_a_learned_model_rates_too_close(square):
    p = Problem(scene=square, start=START, goal=GOAL, waypoints=5, margin=0.02)
    splits = np.array([2, 3, 3, 2])
    assert np.all(distance_bounds(p, gp.CoalModel(), p.goal, splits, 0.02) == 0.02)
    bounds = distance_bounds(p, Underestimating(), p.goal, splits, 0.02)
    d_start, d_goal = gp.signed_distance(square, np.array([START, GOAL])) - 0.25
    assert min(d_start, d_goal) < 0.02  # the stand-in rates an endpoint below the margin
    np.testing.assert_allclose(bounds[:2], min(0.02, d_start - 0.005))
    np.testing.assert_allclose(bounds[2:8], 0.02)
    np.testing.assert_allclose(bounds[8:], min(0.02, d_goal - 0.005))


class GoalDip:
    """A learned stand-in: coal's distance minus a dip of ``depth`` (m) at ``goal`` whose
    width is √(w/2) rad (0.1 rad by default)."""

    name = "goal dip"

    def __init__(self, goal, depth=0.4, w=0.02):
        self.goal, self.depth, self.w = np.asarray(goal), depth, w

    def _dip(self, q):
        return self.depth * np.exp(-np.sum((q - self.goal) ** 2, axis=-1) / self.w)

    def distance(self, scene, q):
        return gp.signed_distance(scene, q) - self._dip(q)

    def distance_and_grad(self, scene, q):
        d, g = gp.signed_distance_and_grad(scene, q)
        dip = self._dip(q)
        return d - dip, g + dip[:, None] * (q - self.goal) * 2 / self.w


def test_ipopt_ignores_a_learned_misjudgement_of_the_fixed_start(square):
    p = Problem(scene=square, start=START, goal=GOAL, waypoints=10)
    model = GoalDip(START, depth=0.5, w=1e-4)  # rates the start itself 0.5 m too close
    assert model.distance(square, np.array([START]))[0] < p.margin
    result = plan(p, collision=model)
    assert result.success, result.reason
    assert result.status in ("Solve_Succeeded", "Solved_To_Acceptable_Level"), result.status


def test_adam_stops_with_a_learned_model_rating_the_goal_below_the_margin(square):
    p = Problem(scene=square, start=START, goal=GOAL, waypoints=20)
    model = GoalDip(GOAL)
    assert model.distance(square, np.array([GOAL]))[0] < 0  # no path has d̂ ≥ margin at the goal
    result = plan(p, collision=model, solver=AdamConfig())
    assert result.status == "adam: cost below threshold", result.reason
    assert result.success, result.reason


TOML = """
[robot]
name = "planar2"
[scene]
generator = "a"
[start]
q = {start}
[goal]
{goal}
[options]
waypoints = 10
margin = 0.02
"""


def _write(tmp_path, text):
    path = tmp_path / "p.toml"
    path.write_text(text)
    return path


def test_from_toml_roundtrip(tmp_path, square):
    path = _write(tmp_path, TOML.format(start=START, goal=f"q = {GOAL}"))
    p = Problem.from_toml(path)
    assert p.waypoints == 10 and p.margin == 0.02 and p.scene.name == "a"
    np.testing.assert_allclose(p.goal, GOAL)


@pytest.mark.parametrize(
    ("start", "goal", "extra", "error", "match"),
    [
        ("[0.0, 0.0, 0.0]", "q = [1.0, 0.0]", "", gp.ProblemFileError, "start.q"),
        ("[0.0, nan]", "q = [1.0, 0.0]", "", gp.ProblemFileError, "start.q: contains NaN"),
        ("[0.0, 0.0]", "q = [1.0, 0.0]", "\nspeed = 3", gp.ProblemFileError, "unknown key"),
        ("[0.0, 0.0]", "q = [1.0, 0.0]\nposition = [1, 1]", "", gp.ProblemFileError, "exactly one"),
        ("[0.0, 0.0", "q = [1.0, 0.0]", "", gp.ProblemFileError, "malformed TOML"),
        ("[0.7, 0.0]", "q = [1.0, 0.0]", "", gp.InfeasibleProblemError, "start.q is in collision"),
        ("[0.0, 0.0]", "position = [2.0, 0.5]", "", gp.InfeasibleProblemError, "out of reach"),
        ("[0.0, 0.0]", "q = [4.0, 0.0]", "", gp.InfeasibleProblemError, "joint limits"),
        ("[0.0, 0.0]", "q = [1.4, 0.0]", "", gp.InfeasibleProblemError, "first link collides"),
    ],
)
def test_bad_problem_files_raise_named_errors(tmp_path, start, goal, extra, error, match):
    path = _write(tmp_path, TOML.format(start=start, goal=goal) + extra)
    with pytest.raises(error, match=match):
        Problem.from_toml(path)


def test_missing_graphdistnet_weights_raise(square, tmp_path):
    p = Problem(scene=square, start=START, goal=GOAL, waypoints=10)
    with pytest.raises(gp.GdnplanError, match="weights"):
        plan(p, collision="graphdistnet", weights=tmp_path / "none.safetensors")


WEIGHTS_A = Path(__file__).resolve().parent.parent / "weights" / "a.safetensors"


@pytest.mark.skipif(not WEIGHTS_A.exists(), reason="no GraphDistNet weights for env a")
def test_ipopt_solves_planar2_around_a_square_with_graphdistnet(square):
    p = Problem(scene=square, start=START, goal=GOAL, waypoints=8)
    result = plan(p, collision="graphdistnet", solver=IpoptConfig(interpolated=1))
    assert result.success, result.reason
    assert result.iterations > 0
    assert verify_path(square, result.q)[0]


class _BatchSizes:
    """A DistanceModel (coal's overall distance) that records the batch size of every call."""

    name = "batch sizes"

    def __init__(self):
        self.coal, self.sizes = CoalModel(), []

    def distance(self, scene, q):
        self.sizes.append(len(q))
        return self.coal.distance(scene, q)

    def distance_and_grad(self, scene, q):
        self.sizes.append(len(q))
        return self.coal.distance_and_grad(scene, q)


@pytest.mark.parametrize(
    ("solver", "interpolated", "points"),
    [("ipopt", None, 2), ("adam", None, 3), ("ipopt", 1, 1), ("adam", 0, 0)],
)
def test_check_points_per_segment_follow_the_solver_default(square, solver, interpolated, points):
    p = Problem(scene=square, start=START, goal=GOAL, waypoints=10)
    model = _BatchSizes()
    kind = {"ipopt": IpoptConfig, "adam": AdamConfig}[solver]
    optimizer = kind() if interpolated is None else kind(interpolated=interpolated)
    opts = PlanConfig(
        SeedConfig(initial="rrt", starts=1), RefineConfig(rounds=0, **SEEDS_ONLY), optimizer
    )
    plan(p, collision=model, solver=opts)
    inner = (p.waypoints - 1) * (points + 1) - 1  # Ipopt has no rows at start and goal
    assert model.sizes[-1] == (inner if solver == "ipopt" else inner + 2)


@pytest.mark.parametrize("initial", ["rrt", "auto"])
def test_negative_interpolated_or_raise_window_raises(square, initial):
    goal = [1.3, -2.5] if initial == "auto" else GOAL  # auto: a free straight line, no solve
    p = Problem(scene=square, start=START, goal=goal, waypoints=10)
    if initial == "auto":
        assert plan(p, collision="coal").status.startswith("straight line certified free")
    seed = SeedConfig(initial=initial)
    for config, name, field in ((IpoptConfig(), "interpolated", "optimizer"),
                                (RefineConfig(), "raise_window", "refine")):  # fmt: skip
        object.__setattr__(config, name, -1)  # forged past the config's own check
        forged = replace(PlanConfig(seed=seed), **{field: config})
        with pytest.raises(gp.GdnplanError, match=name):
            plan(p, collision="coal", solver=forged)


class _Liar(_BatchSizes):
    """Claims 1 m of clearance everywhere (zero gradient): Ipopt straightens every seed path
    through the square and coal rejects it, so every attempt fails."""

    def distance(self, scene, q):  # the overestimate check after a failed round: not recorded
        return np.ones(len(q))

    def distance_and_grad(self, scene, q):  # the NLP's constraint evaluations
        self.sizes.append(len(q))
        return np.ones(len(q)), np.zeros_like(q)


def test_each_restart_adds_a_check_point_per_segment(square):
    p = Problem(scene=square, start=START, goal=GOAL, waypoints=10)
    model = _Liar()
    opts = PlanConfig(SeedConfig(initial="rrt", starts=3), RefineConfig(rounds=0, **SEEDS_ONLY))
    result = plan(p, collision=model, solver=opts)
    assert not result.success and result.attempts == 3
    assert model.sizes[0] == 2  # plan's probe of the model's outputs (planner.check_outputs)
    batches = list(dict.fromkeys(model.sizes[1:]))  # distinct NLP sizes, in order
    assert batches[:3] == [(p.waypoints - 1) * (m + 1) - 1 for m in (2, 3, 4)]


def test_check_point_raise_follows_the_segments_near_the_rejected_ones():
    splits = np.array([2, 4, 2, 2, 2])  # inner check points at t + i / n_t, 0 < s < 5
    raised = np.zeros(5)
    raised[trajopt._near_segments([3], 5, 1)] += 0.1  # segments 2, 3, 4
    s = trajopt._path_parameters(splits)[1:-1]
    expected = np.where(s >= 2.0, 0.1, 0.0)  # waypoint 2 takes the larger of segments 1 and 2
    np.testing.assert_allclose(trajopt._check_point_raise(splits, raised), expected)
    assert trajopt._near_segments([0, 4], 5, 0).tolist() == [True, False, False, False, True]
    assert trajopt._near_segments([2], 5, None).all()  # raise_window=None: the whole path


def test_refine_round_raises_the_margin_only_near_rejected_segments(square, monkeypatch):
    margins = []
    original = trajopt._Transcription.__init__

    def record(self, problem, model, goal, opts, splits, margin, warm=False):
        margins.append((splits.copy(), np.broadcast_to(margin, (int(splits.sum()) - 1,)).copy()))
        original(self, problem, model, goal, opts, splits, margin, warm)

    monkeypatch.setattr(trajopt._Transcription, "__init__", record)
    p = Problem(scene=square, start=START, goal=GOAL, waypoints=12)
    refine = RefineConfig(rounds=1, raise_window=1, exact_rows=False, **SEEDS_ONLY)
    opts = PlanConfig(SeedConfig(initial="rrt", starts=1), refine)
    assert not plan(p, collision=_Liar(), solver=opts).success
    (_, first), (splits, second) = margins
    base = trajopt.check_points.constraint_margin(
        p, opts.refine.clearance_buffer
    )  # margin + buffer
    assert np.all(first == base)
    refined = np.flatnonzero(splits > splits.min())  # the segments coal rejected
    near = trajopt._near_segments(list(refined), len(splits), 1)
    expected_raised = trajopt._check_point_raise(splits, near.astype(float)) > 0
    assert (second > base).tolist() == expected_raised.tolist()
    assert 0 < expected_raised.sum() < len(second)  # some check points keep the plain margin


def test_refine_rounds_raise_to_the_overestimate_not_its_sum(square, monkeypatch):
    """Active check points sit at d̂ = bound, so coal's distance there is bound − (d̂ − d): a
    raise equal to the model's overestimate d̂ − d suffices, and a later round that finds the
    same overestimate must not add it again. _Liar overestimates by 1 m − d (d ≥ −0.5 m in the
    square), so after two rounds the raise stays below 1.5 m (a sum would be over 2 m)."""
    margins = []
    original = trajopt._Transcription.__init__

    def record(self, problem, model, goal, opts, splits, margin, warm=False):
        margins.append(np.broadcast_to(margin, (int(splits.sum()) - 1,)).copy())
        original(self, problem, model, goal, opts, splits, margin, warm)

    monkeypatch.setattr(trajopt._Transcription, "__init__", record)
    p = Problem(scene=square, start=START, goal=GOAL, waypoints=12)
    refine = RefineConfig(rounds=2, raise_window=None, exact_rows=False, **SEEDS_ONLY)
    opts = PlanConfig(SeedConfig(initial="rrt", starts=1), refine)
    assert not plan(p, collision=_Liar(), solver=opts).success
    base = trajopt.check_points.constraint_margin(p, refine.clearance_buffer)
    assert len(margins) == 3
    assert 0.9 < np.max(margins[1] - base) < 1.5
    assert 0.9 < np.max(margins[2] - base) < 1.5


@pytest.mark.parametrize(
    ("settings", "field"),
    [
        ({"refine_rounds": -1}, "refine_rounds"),
        ({"refine_rounds": 100}, "refine_rounds"),
        ({"adam_iterations": 0}, "adam_iterations"),
        ({"max_iter": -5}, "max_iter"),
        ({"starts": 0}, "starts"),
        ({"interpolated": 100_000}, "interpolated"),
        ({"interpolated": "x"}, "interpolated"),
        ({"per_link": "yes"}, "per_link"),
        ({"raise_window": 1.5}, "raise_window"),
        ({"tol": float("nan")}, "tol"),
        ({"learned_margin": float("inf")}, "learned_margin"),
        ({"rrt_clearance": float("nan")}, "rrt_clearance"),
        ({"clearance_buffer": -0.001}, "clearance_buffer"),
        ({"link_cap": -1.0}, "link_cap"),
        ({"rrt_time": -1.0}, "rrt_time"),
        ({"rrt_step": 0.0}, "rrt_step"),
        ({"ccd": 1}, "ccd"),
        ({"initial": "nope"}, "initial"),
        ({"ipopt": {"no_such_option": 1}}, "no_such_option"),
        ({"ipopt": {"mu_init": "x"}}, "mu_init"),
        ({"ipopt": {"mu_strategy": "fast"}}, "mu_strategy"),
        ({"ipopt": {"max_iter": 2.5}}, "max_iter"),
        ({"ipopt": []}, "ipopt"),
    ],
)
def test_deprecated_trajopt_options_reject_bad_settings(settings, field):
    with pytest.raises(gp.InputError, match=field):
        TrajoptOptions(**settings)


@pytest.mark.parametrize(
    ("config", "settings", "field"),
    [
        (RefineConfig, {"rounds": -1}, "rounds"),
        (RefineConfig, {"rounds": 100}, "rounds"),
        (AdamConfig, {"iterations": 0}, "iterations"),
        (AdamConfig, {"lr": 0.0}, "lr"),
        (AdamConfig, {"interpolated": -1}, "interpolated"),
        (IpoptConfig, {"max_iter": -5}, "max_iter"),
        (SeedConfig, {"starts": 0}, "starts"),
        (SeedConfig, {"count": 0}, "count"),
        (SeedConfig, {"count": 51}, "count"),
        (SeedConfig, {"kinds": ("nope",)}, "kinds"),
        (SeedConfig, {"kinds": ()}, "kinds"),
        (SeedConfig, {"kinds": ([],)}, "kinds"),
        (SeedConfig, {"time_budget": 0.0}, "time_budget"),
        (SeedConfig, {"time_budget": float("inf")}, "time_budget"),
        (IpoptConfig, {"interpolated": 100_000}, "interpolated"),
        (IpoptConfig, {"interpolated": None}, "interpolated"),
        (IpoptConfig, {"per_link": "yes"}, "per_link"),
        (RefineConfig, {"raise_window": 1.5}, "raise_window"),
        (IpoptConfig, {"tol": float("nan")}, "tol"),
        (SeedConfig, {"rrt_clearance": float("nan")}, "rrt_clearance"),
        (RefineConfig, {"clearance_buffer": -0.001}, "clearance_buffer"),
        (IpoptConfig, {"link_cap": -1.0}, "link_cap"),
        (SeedConfig, {"rrt_time": -1.0}, "rrt_time"),
        (SeedConfig, {"rrt_step": 0.0}, "rrt_step"),
        (RefineConfig, {"ccd": 1}, "ccd"),
        (SeedConfig, {"initial": "nope"}, "initial"),
        (IpoptConfig, {"options": {"no_such_option": 1}}, "no_such_option"),
        (IpoptConfig, {"options": {"mu_strategy": "fast"}}, "mu_strategy"),
        (IpoptConfig, {"options": []}, "ipopt"),
        (PlanConfig, {"optimizer": "ipopt"}, "optimizer"),
        (PlanConfig, {"seed": RefineConfig()}, "seed"),
    ],
)
def test_configs_reject_bad_settings(config, settings, field):
    with pytest.raises(gp.InputError, match=field):
        config(**settings)


def _cfg(**tables) -> dict:
    cfg = {
        "robot": {"name": "planar2"},
        "scene": {"generator": "a"},
        "start": {"q": [2.006, -0.737]},
        "goal": {"q": [1.448, -2.722]},
    }
    cfg.update(tables)
    return cfg


@pytest.mark.parametrize(
    ("tables", "field"),
    [
        ({"start": {"q": ["2.006", -0.737]}}, "start.q"),
        ({"start": {"q": [True, -0.737]}}, "start.q"),
        ({"start": {"q": [[2.0], -0.737]}}, "start.q"),
        ({"options": {"margin": True}}, "margin"),
        ({"options": {"waypoints": 10**9}}, "waypoints"),
        ({"options": {"waypoints": True}}, "waypoints"),
        ({"options": {"lower": [-10.0, -10.0]}}, "lower"),
        ({"options": {"lower": [0.5, -3.0], "upper": [0.5, 3.0]}}, "lower"),
        ({"solver": {"per_link": "yes"}}, "per_link"),
        ({"solver": {"refine_rounds": -1}}, "refine_rounds"),
        ({"solver": {"ipopt": {"foo": 1}}}, "foo"),
        ({"solver": {"learned_margin": 0.01}}, "learned_margin"),
        ({"solver": {"starts": 2}, "seed": {"starts": 3}}, "starts"),
        ({"ipopt": {"per_link": "yes"}}, "per_link"),
        ({"refine": {"rounds": -1}}, "rounds"),
        ({"ipopt": {"options": {"foo": 1}}}, "foo"),
        ({"seed": {"max_iter": 3}}, r"max_iter: not a \[seed\] key; it belongs in \[ipopt\]"),
        ({"solver": {"rounds": 3}}, r"belongs in \[refine\]"),
        ({"ipopt": {}, "adam": {}}, "at most one"),
        ({"seed": {"kinds": "rrt"}}, "kinds: expected a list"),
        ({"seed": {"time_budget": -1.0}}, "time_budget"),
        (
            {"ipopt": {"interpolated": 50}, "seed": {"starts": 50}, "options": {"waypoints": 500}},
            None,
        ),
    ],
)
def test_problem_config_rejects_bad_values_as_problem_file_errors(tables, field):
    if field is None:  # valid alone, but too many check points together: plan refuses
        problem = Problem.from_config(_cfg(**tables))
        with pytest.raises(gp.InputError, match="check points"):
            plan(problem, collision="coal")
        return
    with pytest.raises(gp.ProblemFileError, match=field):
        Problem.from_config(_cfg(**tables))


@pytest.mark.parametrize(
    "text",
    [b"\xff\xfe\x00garbage", b"x = " + b"[" * 5000 + b"]" * 5000, b"[start\nq = 1"],
)
def test_unreadable_problem_files_are_problem_file_errors(tmp_path, text):
    path = tmp_path / "bad.toml"
    path.write_bytes(text)
    with pytest.raises(gp.ProblemFileError):
        Problem.from_toml(path)


def test_deprecated_names_warn_naming_the_new_ones_and_plan_the_same(square):
    p = Problem(scene=square, start=START, goal=GOAL, waypoints=10)
    with pytest.warns(DeprecationWarning, match="PlanConfig"):
        old = TrajoptOptions(refine_rounds=1, adam_lr=0.02, interpolated=1)
    assert old.to_config("adam") == PlanConfig(
        refine=RefineConfig(rounds=1), optimizer=AdamConfig(lr=0.02, interpolated=1)
    )
    with pytest.warns(DeprecationWarning, match="solver=gdnplan.PlanConfig"):
        via_old = plan(p, collision="coal", options=old)
    new = plan(p, collision="coal", solver=old.to_config("ipopt"))
    np.testing.assert_array_equal(via_old.q, new.q)
    with pytest.warns(DeprecationWarning, match=r"solver=gdnplan.AdamConfig\(\)"):
        adam = plan(p, collision="coal", solver="adam")
    np.testing.assert_array_equal(adam.q, plan(p, collision="coal", solver=AdamConfig()).q)
    with pytest.warns(DeprecationWarning, match="IpoptConfig"):
        plan(p, collision="coal", solver="ipopt")
    with pytest.raises(gp.InputError, match="learned_margin"), pytest.warns(DeprecationWarning):
        TrajoptOptions(learned_margin=0.01).to_config()


def test_old_solver_table_loads_into_the_new_configs_with_a_warning():
    assert issubclass(FutureWarning, Warning) and not issubclass(FutureWarning, DeprecationWarning)
    old = _cfg(solver={"rrt_step": 0.3, "refine_rounds": 2, "interpolated": 3, "ipopt": {}})
    with pytest.warns(FutureWarning, match=r"refine_rounds → \[refine\] rounds"):
        problem = Problem.from_config(old)  # a user-facing deprecation: shown by default
    new = _cfg(seed={"rrt_step": 0.3}, refine={"rounds": 2}, ipopt={"interpolated": 3})
    assert problem.solver == Problem.from_config(new).solver
    with pytest.warns(FutureWarning):
        adam = Problem.from_config(_cfg(solver={"adam_lr": 0.02, "interpolated": 2}))
    assert adam.solver.optimizer == AdamConfig(lr=0.02, interpolated=2)


@pytest.mark.parametrize("collision", ["coal", "distance_model"])
def test_weights_with_a_model_that_loads_none_are_refused(square, collision):
    """Weights beside collision='coal' (or a model instance) would be silently unused."""
    problem = gp.Problem(square, np.array(START), np.array(GOAL))
    model = CoalModel() if collision == "distance_model" else collision
    with pytest.raises(gp.InputError, match=r"^weights: only collision='graphdistnet'"):
        gp.plan(problem, collision=model, weights="b")
