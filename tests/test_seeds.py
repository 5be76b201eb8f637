"""Several seeds, the cheapest certified path, the time budget (gdnplan.trajopt.seeds, ipopt)."""

from __future__ import annotations

import json
from dataclasses import replace

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, example, given, settings
from hypothesis import strategies as st

import gdnplan as gp
from gdnplan.ccd import certify_path
from gdnplan.cli import run
from gdnplan.errors import InfeasibleProblemError
from gdnplan.trajopt import (
    PlanConfig,
    Problem,
    RefineConfig,
    SeedConfig,
    SeedRequest,
    plan,
    register_seed_kind,
    straight_line,
)
from gdnplan.trajopt.config import SEED_KINDS


def assert_certified(problem: Problem, result) -> None:
    """Success means the coal certificate proves the whole path above the certified clearance."""
    assert result.min_distance > problem.certified_clearance
    assert certify_path(problem.scene, result.q, problem.certified_clearance).ok


def unpolished(count: int) -> PlanConfig:
    """``count`` seeds, no polish solve after them (:mod:`gdnplan.trajopt.polish`)."""
    return PlanConfig(seed=SeedConfig(count=count), refine=RefineConfig(polish=False))


def random_problem(scene_seed: int, q_seed: int) -> Problem:
    """A planar2 problem in environment (b) whose straight line collides (None-free: assume)."""
    scene = gp.make_scene("b", seed=scene_seed)
    q = scene.robot.sample(2, seed=q_seed)
    try:
        problem = Problem(scene, q[0], q[1], waypoints=12, margin=0.02)
    except InfeasibleProblemError:
        assume(False)
    line = straight_line(problem.start, problem.goal, problem.waypoints)
    assume(not certify_path(scene, line, problem.margin, stop_early=True).ok)
    return problem


@pytest.mark.slow  # ~30 s: five random problems, each planned with one and three seeds
@settings(max_examples=5, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(scene_seed=st.integers(0, 10_000), q_seed=st.integers(0, 10_000), seed=st.integers(0, 50))
def test_more_seeds_never_return_a_costlier_certified_plan(scene_seed, q_seed, seed):
    problem = random_problem(scene_seed, q_seed)
    # without the polish (its solve from the winner may end a hair above a polish of a costlier
    # seed's path): the claim is the seeds' choice
    one = plan(problem, collision="coal", solver=unpolished(1), seed=seed)
    cfg = unpolished(3)
    three = plan(problem, collision="coal", solver=cfg, seed=seed)
    for result in (one, three):
        if result.success:
            assert_certified(problem, result)
            assert 0 <= result.seed.index < max(result.attempts, 1)
            assert result.seed.stream == seed + result.seed.index
    if one.success:  # the first seed of three is the one seed: same stream, same solve
        assert three.success
        assert three.path_cost <= one.path_cost + 1e-12
        assert three.attempts >= one.attempts


def test_several_seeds_are_deterministic_and_report_the_winner():
    problem = Problem.from_toml("planar2_square")
    cfg = unpolished(4)
    a = plan(problem, collision="coal", solver=cfg, seed=5)
    b = plan(problem, collision="coal", solver=cfg, seed=5)
    np.testing.assert_array_equal(a.q, b.q)
    assert a.seed == b.seed and a.attempts == b.attempts == 4
    assert a.seed.kind == "rrt" and "least path cost of 4 certified" in a.reason
    assert_certified(problem, a)
    one = unpolished(1)
    single = plan(problem, collision="coal", solver=one, seed=5)  # the first of the four seeds
    assert a.path_cost <= single.path_cost + 1e-12


@pytest.mark.parametrize("stream", [0, 1, 2])
def test_a_via_seed_passes_its_via_point_on_certified_edges(stream):
    from gdnplan.trajopt.seeds import via_seed

    problem = Problem.from_toml("planar2_square")
    request = SeedRequest(problem, problem.goal, problem.margin, stream, 0, 5.0, 2.0)
    path = via_seed(request)
    if path is None:  # the via point lay where RRT-Connect found no way: allowed
        return
    assert path.shape == (problem.waypoints, 2)
    np.testing.assert_allclose(path[[0, -1]], [problem.start, problem.goal])
    assert certify_path(problem.scene, path, problem.margin).ok


def test_a_registered_seed_kind_is_drawn_in_turn(monkeypatch):
    """A new seed source is one function (how another planner's paths would come in)."""
    calls = []

    def arc(request: SeedRequest):
        calls.append(request.stream)
        p = request.problem
        guess = straight_line(p.start, request.goal, p.waypoints)
        guess[1:-1, 1] += 1.5 * np.sin(np.linspace(0, np.pi, p.waypoints))[1:-1]  # elbow detour
        return np.clip(guess, p.lower, p.upper)

    monkeypatch.setitem(SEED_KINDS, "probe", None)  # removed again after the test
    register_seed_kind("probe", arc)
    problem = Problem.from_toml("planar2_square")
    cfg = PlanConfig(seed=SeedConfig(count=2, kinds=("rrt", "probe")))
    result = plan(problem, collision="coal", solver=cfg, seed=3)
    assert calls == [4]  # seed 1 of the call: stream 3 + 1
    assert result.success and result.attempts == 2
    assert_certified(problem, result)
    with pytest.raises(gp.InputError, match="kinds"):
        SeedConfig(kinds=("no_such_kind",))
    with pytest.raises(gp.InputError, match="identifier"):
        register_seed_kind("not a name", arc)


def test_a_seed_kind_of_the_wrong_shape_is_an_input_error(monkeypatch):
    monkeypatch.setitem(SEED_KINDS, "short", lambda request: np.zeros((2, 2)))
    problem = Problem.from_toml("planar2_square")
    with pytest.raises(gp.InputError, match="shape"):
        plan(problem, collision="coal", solver=PlanConfig(seed=SeedConfig(kinds=("short",))))


HOSTILE_GUESSES = {  # what a caller's seed kind might return instead of a (T, dof) path
    "strings": lambda t, n: [["a"] * n] * t,  # ValueError from np.asarray(dtype=float)
    "ragged": lambda t, n: [[0.0] * n] * (t - 1) + [[0.0]],  # ValueError (inhomogeneous)
    "dict": lambda t, n: {"q": 0},  # TypeError
    "complex": lambda t, n: np.full((t, n), 0.5 + 1j),  # the imaginary part silently dropped
    "bool": lambda t, n: np.ones((t, n), bool),  # planned from 1 rad
    "nan": lambda t, n: np.full((t, n), np.nan),  # Invalid_Number_Detected / "q: contains NaN"
    "inf": lambda t, n: np.full((t, n), -np.inf),
    "object": lambda t, n: np.array([[0.1, None]] * t, dtype=object)[:, :n],
}


@settings(max_examples=12, deadline=None)
@given(name=st.sampled_from(sorted(HOSTILE_GUESSES)), row=st.integers(0, 19))
@example(name="strings", row=0)
@example(name="complex", row=3)
def test_a_seed_kind_returning_no_real_finite_path_is_an_input_error(name, row):
    """A seed kind's path must be real finite numbers of shape (T, dof): anything else is an
    InputError naming the kind, before any solve (one bad row is enough)."""
    from gdnplan.trajopt.seeds import checked_guess

    problem = Problem.from_toml("planar2_square")
    t, n = problem.waypoints, problem.scene.robot.dof
    bad = HOSTILE_GUESSES[name](t, n)
    if isinstance(bad, np.ndarray) and bad.shape == (t, n):  # one bad row in a good path
        good = straight_line(problem.start, problem.goal, t).astype(bad.dtype)
        good[row] = bad[row]
        bad = good
    with pytest.raises(gp.InputError, match="seed kind 'probe'"):
        checked_guess("probe", bad, problem)
    with pytest.MonkeyPatch.context() as patch:
        patch.setitem(SEED_KINDS, "probe", lambda request: bad)
        cfg = PlanConfig(seed=SeedConfig(initial="rrt", kinds=("probe",), count=1, starts=1))
        with pytest.raises(gp.InputError, match="seed kind 'probe'"):
            plan(problem, collision="coal", solver=cfg)
    line = straight_line(problem.start, problem.goal, t)
    for fine in (line.tolist(), line.astype(np.float32), np.rint(line).astype(int)):
        np.testing.assert_array_equal(checked_guess("probe", fine, problem), np.asarray(fine))


class FakeClock:
    """A ``time`` module stand-in for the planner: ``perf_counter`` advances 1 µs a call, and
    ``step`` seconds whenever :meth:`tick` (a seed kind's work) runs."""

    def __init__(self) -> None:
        self.now = 1000.0

    def perf_counter(self) -> float:
        self.now += 1e-6
        return self.now

    def tick(self, seconds: float) -> None:
        self.now += seconds


@pytest.fixture
def fake_clock(monkeypatch) -> FakeClock:
    """The planner's clock (``time`` in plan, seeds, solves and the result) is a FakeClock."""
    from gdnplan.trajopt import ipopt, planner, result, seeds

    clock = FakeClock()
    for module in (planner, seeds, ipopt, result):
        monkeypatch.setattr(module, "time", clock)
    return clock


def test_the_time_budget_is_kept_within_one_solve(fake_clock, monkeypatch):
    """Anytime mode on an injected clock: each seed takes 10 s, the budget is 25 s, so seeds 0
    and 1 are refined and certified, seed 2 is drawn (the clock then says 30 s) but no solve
    starts after the deadline, and the cheaper of the two certified paths comes back; the
    call's time is the clock's (Ipopt's own wall-time cap, the time left, is ≥ 5 s real)."""
    streams = []

    def slow_arc(request: SeedRequest):
        streams.append(request.stream)
        fake_clock.tick(10.0)
        p = request.problem
        guess = straight_line(p.start, request.goal, p.waypoints)
        bend = (1.5 - 0.3 * request.index) * np.sin(np.linspace(0, np.pi, p.waypoints))[1:-1]
        guess[1:-1, 1] += bend
        return np.clip(guess, p.lower, p.upper)

    monkeypatch.setitem(SEED_KINDS, "slow", slow_arc)
    problem = Problem.from_toml("planar2_square")
    cfg = PlanConfig(seed=SeedConfig(initial="rrt", kinds=("slow",), time_budget=25.0))
    result = plan(problem, collision="coal", solver=cfg, seed=7)
    assert streams == [7, 8, 9]  # the third seed was drawn before the deadline
    assert result.attempts == 3
    assert result.success and result.seed.index in (0, 1)
    assert_certified(problem, result)
    assert "least path cost of 2 certified" in result.reason
    assert 30.0 <= result.solve_time < 30.1  # the clock's seconds, not the machine's
    unbudgeted = plan(problem, collision="coal", solver=PlanConfig(seed=SeedConfig(
        initial="rrt", kinds=("slow",), count=2)), seed=7)  # fmt: skip
    assert unbudgeted.attempts == 2 and 20.0 <= unbudgeted.solve_time < 20.1


def test_failed_seeds_draw_new_ones_within_the_budget(fake_clock, monkeypatch):
    """Within a time budget a seed that finds no path does not end the call after ``starts``
    failures: the next seed is drawn until the budget ends (here 5 failures, then a path; a
    seed that finds none is asked once more at the margin alone, so a failure costs 1 s)."""

    def sometimes(request: SeedRequest):
        fake_clock.tick(0.5)
        if request.index < 5:
            return None
        p = request.problem
        guess = straight_line(p.start, request.goal, p.waypoints)
        guess[1:-1, 1] += 1.5 * np.sin(np.linspace(0, np.pi, p.waypoints))[1:-1]
        return np.clip(guess, p.lower, p.upper)

    monkeypatch.setitem(SEED_KINDS, "sometimes", sometimes)
    problem = Problem.from_toml("planar2_square")
    seeds = SeedConfig(initial="rrt", kinds=("sometimes",), starts=2, time_budget=6.5)
    result = plan(problem, collision="coal", solver=PlanConfig(seed=seeds))
    assert result.success and result.seed.index == 5, result.reason
    assert_certified(problem, result)
    unbudgeted = PlanConfig(seed=replace(seeds, time_budget=None))
    without = plan(problem, collision="coal", solver=unbudgeted)
    assert not without.success and without.attempts == 2  # starts = 2 failures end it


def test_a_budget_too_short_for_any_seed_fails_instead_of_returning_an_uncertified_path():
    problem = Problem.from_toml("planar7_d")
    cfg = PlanConfig(seed=SeedConfig(time_budget=1e-6, initial="rrt"))
    result = plan(problem, collision="coal", solver=cfg)
    assert not result.success and "time budget" in result.reason
    assert result.seed is None


def cli(args: list[str], capsys) -> tuple[int, str, str]:
    """Exit status, stdout and stderr of ``gdnplan ARGS`` (as the console script runs it)."""
    with pytest.raises(SystemExit) as done:
        run(args)
    out = capsys.readouterr()
    return done.value.code, out.out, out.err


def test_plan_json_names_the_winning_seed_and_the_seeds_tried(capsys):
    args = ["plan", "planar2_square", "--collision", "coal", "--seeds", "2", "--json", "-q"]
    code, out, err = cli(args, capsys)
    assert code == 0, err
    summary = json.loads(out)
    assert summary["attempts"] == 2
    assert summary["seed"]["kind"] == "rrt" and summary["seed"]["index"] in (0, 1)


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--seeds", "0"], "--seeds/--time-budget: count"),
        (["--time-budget", "-1"], "time_budget"),
        (["--solver", "adam", "--seeds", "2"], "--seeds: Adam"),
        (["--solver", "bfgs"], "--solver: unknown"),
    ],
)
def test_plan_flags_that_do_not_apply_are_input_errors(args, message, capsys):
    code, _, err = cli(["plan", "planar2_square", "--collision", "coal", "-q", *args], capsys)
    assert code == 2 and err.count("\n") == 1
    assert err.startswith("error: ") and message in err, err


def test_an_aorrtc_seed_is_refined_and_certified():
    pytest.importorskip("ompl")
    problem = Problem.from_toml("planar2_square")
    cfg = PlanConfig(seed=SeedConfig(kinds=("aorrtc",), count=1))
    result = plan(problem, collision="coal", solver=cfg)
    assert result.success, result.reason
    assert result.seed.kind == "aorrtc"
    assert_certified(problem, result)


def test_an_aorrtc_seed_of_a_large_plan_seed_runs():
    """plan(seed=…) takes up to 2⁶²; OMPL's seed is 32-bit (plan_ompl refuses more)."""
    pytest.importorskip("ompl")
    from gdnplan.limits import MAX_SEED

    problem = Problem.from_toml("planar2_square")
    cfg = PlanConfig(seed=SeedConfig(kinds=("aorrtc",), count=1))
    result = plan(problem, collision="coal", solver=cfg, seed=MAX_SEED)
    assert result.success, result.reason


def test_a_seed_kind_whose_dependency_is_missing_says_how_to_install_it(monkeypatch):
    from gdnplan.trajopt.config import MISSING_SEED_KINDS

    monkeypatch.delitem(SEED_KINDS, "aorrtc", raising=False)
    monkeypatch.setitem(MISSING_SEED_KINDS, "aorrtc", "needs OMPL, which is not installed (…)")
    with pytest.raises(gp.InputError, match="kinds: seed kind 'aorrtc' needs OMPL"):
        SeedConfig(kinds=("rrt", "aorrtc"))


def test_an_rrt_seed_is_the_cheapest_of_its_draws(monkeypatch):
    """The rrt kind draws SCREENED RRT-Connect paths and returns the one of least Σ‖Δq‖²."""
    from gdnplan.trajopt import seeds

    problem = Problem.from_toml("planar2_square")
    request = SeedRequest(problem, problem.goal, problem.margin, 2, 0, 30.0, 2.0)
    monkeypatch.setattr(seeds, "SCREENED", 1)
    first = seeds.rrt_seed(request)
    monkeypatch.setattr(seeds, "SCREENED", 4)
    best = seeds.rrt_seed(request)
    monkeypatch.setattr(seeds, "SCREENED", 1)
    draws = [seeds.rrt_seed(replace(request, seed=2 + seeds.SCREEN_STRIDE * j)) for j in range(4)]
    costs = [np.sum(np.diff(d, axis=0) ** 2) for d in draws if d is not None]
    np.testing.assert_array_equal(draws[0], first)
    assert np.sum(np.diff(best, axis=0) ** 2) == pytest.approx(min(costs))
    assert certify_path(problem.scene, best, problem.margin).ok


class _SlowClock:
    """A clock that advances ``tick`` s every time it is read: a machine slower or busier than
    any real one."""

    def __init__(self, tick: float) -> None:
        self.now, self.tick = 0.0, tick

    def perf_counter(self) -> float:
        self.now += self.tick
        return self.now


@pytest.mark.parametrize("name", ["planar2_square", "planar7_d"])
def test_an_rrt_seed_does_not_depend_on_the_clock(name, monkeypatch):
    """Every screening draw runs however slow the clock (within the seed's time limit), and
    the seed equals the one of a normal clock: the same problem and stream give the same seed
    at any load."""
    from gdnplan.trajopt import seeds

    problem = Problem.from_toml(name)
    request = SeedRequest(problem, problem.goal, problem.margin, 2, 0, 30.0, 0.5)
    normal = seeds.rrt_seed(request)
    draws = []
    real = seeds.seed_path

    def counted(*args, **kwargs):
        draws.append(kwargs["seed"])
        return real(*args, **kwargs)

    monkeypatch.setattr(seeds, "seed_path", counted)
    monkeypatch.setattr(seeds, "time", _SlowClock(0.9))
    slow = seeds.rrt_seed(request)
    assert len(draws) == seeds.SCREENED
    assert normal is not None and slow is not None
    np.testing.assert_array_equal(slow, normal)


@settings(max_examples=8, deadline=None)
@given(stream=st.integers(0, 1000), kind=st.sampled_from(["rrt", "via"]))
@example(stream=0, kind="rrt")
def test_a_seed_stays_within_the_problem_joint_limits(stream, kind):
    """Problem(lower=…, upper=…) narrows the robot's joint limits: every seed kind samples
    within them. The rrt kind sampled the robot's own limits, so its seed left the problem's box
    (Ipopt then clipped it into collision), and on a goal enclosed by the narrowed limits
    RRT-Connect "found" a path around the obstacle outside them."""
    from gdnplan.trajopt.seeds import SEED_KINDS

    base = Problem.from_toml("planar2_square")
    lower, upper = np.array([1.3, -2.9]), np.array([2.2, -0.5])
    problem = replace_limits(base, lower, upper)
    request = SeedRequest(problem, problem.goal, problem.margin, stream, 0, 5.0, 2.0)
    path = SEED_KINDS[kind](request)
    if path is not None:
        assert np.all((path >= lower) & (path <= upper))
    enclosed = Problem(  # joint 0 held within 0.02 rad of 1.0: the forearm cannot get round
        base.scene, [1.0, -2.9], [1.0, 0.5], lower=[0.98, -3.14], upper=[1.02, 3.14]
    )
    request = SeedRequest(enclosed, enclosed.goal, enclosed.margin, stream, 0, 0.5, 2.0)
    path = SEED_KINDS[kind](request)
    assert path is None or np.all((path >= enclosed.lower) & (path <= enclosed.upper))


def replace_limits(problem: Problem, lower, upper) -> Problem:
    """``problem`` with narrowed joint limits [lower, upper] (rad)."""
    return Problem(
        problem.scene, problem.start, problem.goal, waypoints=problem.waypoints,
        margin=problem.margin, lower=lower, upper=upper,
    )  # fmt: skip


@pytest.mark.parametrize("seed", [np.int64(5), np.uint32(5), np.int8(5)])
def test_a_numpy_seed_gives_the_plan_of_its_int_and_json_ready_seed_info(seed):
    """plan(seed=np.int64(5)) plans as seed=5; the winner's SeedInfo held numpy integers
    (stream = seed + index), which json.dumps refused."""
    problem = Problem.from_toml("planar2_square")
    cfg = unpolished(2)
    ours, theirs = plan(problem, "coal", solver=cfg, seed=seed), plan(problem, "coal", cfg, seed=5)
    np.testing.assert_array_equal(ours.q, theirs.q)
    assert type(ours.seed.stream) is int and type(ours.seed.index) is int
    assert json.loads(json.dumps(ours.seed.summary())) == theirs.seed.summary()
