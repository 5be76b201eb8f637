"""Exact coal rows in refine rounds of a learned model (gdnplan.trajopt.refine)."""

from __future__ import annotations

import numpy as np
import pytest

import gdnplan as gp
from gdnplan.ccd import certify_path
from gdnplan.trajopt import PlanConfig, Problem, RefineConfig, SeedConfig, plan
from gdnplan.trajopt.check_points import (
    _check_point_raise,
    _interpolation_matrix,
    _near_segments,
    _path_parameters,
)
from gdnplan.trajopt.refine import (
    ExactRows,
    exact_check_points,
    underestimated_segments,
    with_exact_rows,
)

START, GOAL = [1.3, -2.9], [1.5, 0.1]  # planar2 around env a's square; the straight line hits it


@pytest.fixture(scope="module")
def square():
    return gp.make_scene("a")


class Liar:
    """Claims 1 m of clearance everywhere with a zero gradient: every path looks free."""

    name = "liar"

    def distance(self, scene, q):
        return np.ones(len(np.atleast_2d(q)))

    def distance_and_grad(self, scene, q):
        q = np.atleast_2d(q)
        return np.ones(len(q)), np.zeros_like(q)


class DeferredLiar(Liar):
    def distance_deferred_grad(self, scene, q):
        q = np.atleast_2d(q)
        return np.ones(len(q)), lambda: np.full(q.shape, 7.0)


def test_exact_check_points_are_those_of_the_marked_segments():
    splits = np.array([2, 4, 2, 2, 2])
    exact = np.array([False, False, True, False, True])
    mask = exact_check_points(splits, exact)
    s = _path_parameters(splits)[1:-1]  # inner check points, 0 < s < 5
    expected = ((s >= 2) & (s <= 3)) | (s >= 4)  # a waypoint is exact when a neighbour is
    assert mask.tolist() == expected.tolist()
    assert mask.tolist() == (_check_point_raise(splits, exact.astype(float)) > 0).tolist()


@pytest.mark.parametrize("model", [Liar(), DeferredLiar()], ids=["plain", "deferred"])
def test_exact_rows_are_coal_at_their_check_points_and_the_model_elsewhere(square, model):
    q = square.robot.sample(9, seed=3)
    mask = np.array([True, False, False, True, True, False, True, False, False])
    mixed = ExactRows(model, mask)
    d_coal, g_coal = gp.signed_distance_and_grad(square, q)
    d, g = mixed.distance_and_grad(square, q)
    np.testing.assert_allclose(d[mask], d_coal[mask])
    np.testing.assert_allclose(g[mask], g_coal[mask])
    assert np.all(d[~mask] == 1.0) and np.all(g[~mask] == 0.0)
    np.testing.assert_allclose(mixed.distance(square, q), d)
    other = mixed.distance(square, q[:4])  # another batch than the check points: the model's
    assert np.all(other == 1.0)
    if isinstance(model, DeferredLiar):
        d2, grad = mixed.distance_deferred_grad(square, q)
        np.testing.assert_allclose(d2, d)
        g2 = grad()
        np.testing.assert_allclose(g2[mask], g_coal[mask])
        assert np.all(g2[~mask] == 7.0)
    else:
        assert not hasattr(mixed, "distance_deferred_grad")
    assert with_exact_rows(model, np.array([2, 2]), np.zeros(2, bool)) is model


def test_a_model_that_lies_everywhere_is_certified_once_coal_rows_cover_the_path(square):
    """The liar rates every path free, so Ipopt keeps the seed's straightened path through the
    square and coal rejects it; with exact rows on the whole path (raise_window None) the next
    round is coal's own NLP, and its path is certified. Raising the liar's bound (the old rule)
    cannot fix a zero gradient: that plan fails."""
    p = Problem(scene=square, start=START, goal=GOAL, waypoints=12)
    seeds = SeedConfig(initial="rrt", starts=1, count=1)
    exact = plan(p, collision=Liar(), solver=PlanConfig(seeds, RefineConfig(raise_window=None)))
    assert exact.success, exact.reason
    assert certify_path(square, exact.q, p.certified_clearance).ok
    raised = RefineConfig(raise_window=None, exact_rows=False)
    assert not plan(p, collision=Liar(), solver=PlanConfig(seeds, raised)).success


PATH = 6  # waypoints of the underestimation tests' path


class Pessimist:
    """Coal's distance less 0.6 m where the first joint is above −2.45 rad: a model that rates
    a free region as in contact (its gradient coal's)."""

    name = "pessimist"

    def _offset(self, q):
        return np.where(np.atleast_2d(q)[:, 0] > -2.45, 0.6, 0.0)

    def distance(self, scene, q):
        return gp.signed_distance(scene, np.atleast_2d(q)) - self._offset(q)

    def distance_and_grad(self, scene, q):
        d, g = gp.signed_distance_and_grad(scene, np.atleast_2d(q))
        return d - self._offset(q), g


def test_underestimated_segments_are_where_the_model_alone_violates_the_bound(square):
    """A path (T = 6) whose first joint runs from −3.1 to −2.1 rad, clear of the square by
    ≥ 0.5 m: the check points with q_0 > −2.45 have d̂ = d − 0.6 m below the bound while coal
    clears it, so exactly the segments holding one (ends included) are marked, with the window
    either side; coal itself marks nothing, and neither does a bound below every d̂."""
    q = np.linspace([-3.1, -1.0], [-2.1, -1.0], PATH)
    splits = np.full(PATH - 1, 3)
    points = _interpolation_matrix(splits)[1:-1] @ q
    bound = 0.04
    assert np.all(gp.signed_distance(square, points) >= bound + 0.4)  # the premise
    marked = underestimated_segments(square, Pessimist(), q, splits, bound, 0)
    s = _path_parameters(splits)[1:-1]
    low = points[:, 0] > -2.45
    expected = np.array([np.any(low & (s >= t) & (s <= t + 1)) for t in range(PATH - 1)])
    assert marked.tolist() == expected.tolist() and marked.any() and not marked.all()
    wide = underestimated_segments(square, Pessimist(), q, splits, bound, 1)
    assert wide.tolist() == _near_segments(np.flatnonzero(expected).tolist(), PATH - 1, 1).tolist()
    assert not underestimated_segments(square, gp.CoalModel(), q, splits, bound, None).any()
    assert not underestimated_segments(square, Pessimist(), q, splits, -1.0, None).any()


def test_coal_rows_before_the_first_solve_where_the_model_underestimates(square, monkeypatch):
    """_solve_refined builds its first NLP with coal rows on the underestimated segments: the
    distance model of the first transcription is ExactRows with those check points exact."""
    from gdnplan.trajopt import ipopt as ipopt_module

    seen = []
    real = ipopt_module._Transcription

    def spy(problem, model, *args, **kwargs):
        seen.append(model)
        return real(problem, model, *args, **kwargs)

    monkeypatch.setattr(ipopt_module, "_Transcription", spy)
    q = np.linspace([-3.1, -1.0], [-2.1, -1.0], PATH)
    p = Problem(scene=square, start=q[0], goal=q[-1], waypoints=PATH, margin=0.04)
    cfg = PlanConfig(refine=RefineConfig(rounds=0, raise_window=0))
    run = ipopt_module._Run(q=q)
    ipopt_module._solve_refined(p, Pessimist(), q[-1], cfg, q, run)
    first = seen[0]
    assert isinstance(first, ExactRows)
    splits = np.full(PATH - 1, cfg.optimizer.interpolated + 1)
    margin = ipopt_module.constraint_margin(p, cfg.refine.clearance_buffer)
    marked = underestimated_segments(square, Pessimist(), q, splits, margin, 0)
    assert marked.any()
    assert first.exact.tolist() == exact_check_points(splits, marked).tolist()


def _trace_exact_rows(monkeypatch) -> list[tuple[str, np.ndarray | None]]:
    """Events of a plan, in order: ("seed", None) when a seed is drawn, ("again", run.exact)
    when a polish or repair solve starts, ("rows", segment mask) for every NLP built."""
    from gdnplan.trajopt import ipopt as ipopt_module
    from gdnplan.trajopt import polish as polish_module

    events: list[tuple[str, np.ndarray | None]] = []
    rows, draw, again = ipopt_module.with_exact_rows, ipopt_module.draw_seed, polish_module._again

    def on_rows(model, splits, exact, offset=0.0):
        events.append(("rows", exact.copy()))
        return rows(model, splits, exact, offset)

    def on_seed(*args, **kwargs):
        events.append(("seed", None))
        return draw(*args, **kwargs)

    def on_again(problem, model, goal, cfg, run, deadline):
        events.append(("again", None if run.exact is None else run.exact.copy()))
        return again(problem, model, goal, cfg, run, deadline)

    monkeypatch.setattr(ipopt_module, "with_exact_rows", on_rows)
    monkeypatch.setattr(ipopt_module, "draw_seed", on_seed)
    monkeypatch.setattr(polish_module, "_again", on_again)
    return events


def test_a_polish_starts_with_the_coal_rows_of_the_solve_that_made_its_path(square, monkeypatch):
    """The liar's seed solves are rejected and end with coal rows on some segments; each seed
    starts afresh (no coal rows: the liar underestimates nowhere), and each polish solve's
    first NLP has coal rows on at least the segments of the solve that made its path."""
    events = _trace_exact_rows(monkeypatch)
    p = Problem(scene=square, start=START, goal=GOAL, waypoints=12)
    cfg = PlanConfig(SeedConfig(initial="rrt", starts=2, count=2), RefineConfig(raise_window=1))
    result = plan(p, collision=Liar(), solver=cfg)
    assert result.success, result.reason
    kinds = [kind for kind, _ in events]
    starts = [i for i, kind in enumerate(kinds) if kind in ("seed", "again")]
    assert kinds.count("seed") == 2 and "again" in kinds
    for i in starts:
        first = next(mask for kind, mask in events[i + 1 :] if kind == "rows")
        if kinds[i] == "seed":
            assert not first.any()
        else:
            carried = events[i][1]
            assert carried is not None and carried.any()
            assert np.all(first[carried])
    ends = [*starts[1:], len(events)]  # each seed attempt's last NLP: its final coal rows
    finals = [
        [mask for kind, mask in events[i:end] if kind == "rows"][-1]
        for i, end in zip(starts, ends, strict=True)
        if kinds[i] == "seed"
    ]
    polish_first = next(i for i in starts if kinds[i] == "again")
    assert any(np.array_equal(events[polish_first][1], m) for m in finals)


def test_3d_coal_rows_hold_contact_only_pairs_to_contact_not_the_margin():
    """The UR5e's forearm–wrist pairs never leave a 2 cm margin (contact-only,
    gdnplan.arm3d.pairs): coal rows of a learned 3-D plan count them as d + margin, as the
    planner's coal model and the certificate do, so a row ≥ margin asks them for d ≥ 0 only,
    not for a clearance they can never have (every row would be violated)."""
    from gdnplan.arm3d import Scene3D, load_robot3d, signed_distance3d
    from gdnplan.arm3d.distance3d import Coal3DModel
    from gdnplan.trajopt.refine import ExactRows

    robot = load_robot3d("ur5e")
    scene = Scene3D(robot, [])
    q = robot.random_configurations(40, np.random.default_rng(0))
    rows = ExactRows(Coal3DModel(), np.ones(len(q), bool), offset=0.02)
    d, g = rows.distance_and_grad(scene, q)
    want, want_g = Coal3DModel(contact_offset=0.02).distance_and_grad(scene, q)
    np.testing.assert_allclose(d, want)
    np.testing.assert_allclose(g, want_g)
    true = signed_distance3d(scene, q)
    assert true.max() < 0.02 < d.max()  # without the offset no row could reach the margin
