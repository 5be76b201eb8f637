"""Table II: problem generation, the common-problem path-cost rule, the CLI end to end."""

from __future__ import annotations

import json
from dataclasses import replace

import numpy as np
import pytest
from typer.testing import CliRunner

import gdnplan as gp
from gdnplan import table2
from gdnplan.cli import app
from gdnplan.trajopt import straight_line


def test_reaching_problems_are_deterministic_clear_at_the_ends_blocked_between_and_solvable():
    problems = table2.reaching_problems("b", n=3, seed=5)
    again = table2.reaching_problems("b", n=3, seed=5)
    for p, q in zip(problems, again, strict=True):
        np.testing.assert_array_equal(p.start, q.start)
        np.testing.assert_array_equal(p.goal, q.goal)
        ends = gp.signed_distance(p.scene, np.stack([p.start, p.goal]))
        assert np.all(ends > p.margin + 0.03)
        line = straight_line(p.start, p.goal, p.waypoints)
        assert not gp.verify_path(p.scene, line, margin=p.margin)[0]
        assert gp.plan(p, collision="coal").success  # a solvable problem


class _SlowClock:
    """A stand-in for :mod:`time` in :mod:`gdnplan.rrt` whose clock runs ``step`` s per call:
    a machine far slower (or busier) than this one."""

    def __init__(self, step: float) -> None:
        self.now, self.step = 0.0, step

    def perf_counter(self) -> float:
        self.now += self.step
        return self.now


def test_reaching_problems_do_not_depend_on_the_machines_speed(monkeypatch):
    """The same problems on a machine whose clock runs far ahead of its RRT-Connect: the
    selection's solvability test is an iteration cap, not a time limit (once, under load, a
    10 s limit turned (d) problem 14 away and shifted every later index by one)."""
    n = 3
    fast = table2.reaching_problems("b", n=n, seed=0)
    clock = _SlowClock(2.0)  # every clock reading 2 s after the last
    monkeypatch.setattr(gp.rrt, "time", clock)
    slow = table2.reaching_problems("b", n=n, seed=0)
    assert clock.now > 10.0  # the old 10 s limit would have been passed
    for p, q in zip(fast, slow, strict=True):
        np.testing.assert_array_equal(p.start, q.start)
        np.testing.assert_array_equal(p.goal, q.goal)


def test_fetch_problems_are_unseen_random_layouts():
    problems = table2.reaching_problems("fetch", n=2, seed=0)
    assert [p.scene.seed for p in problems] == [1, 2]
    assert problems[0].waypoints == table2.WAYPOINTS["fetch"]


def _record(method: str, problem: int, success: bool, cost: float) -> table2.Record:
    return table2.Record("b", method, "ipopt", problem, success, 1.0, 0.0, cost, 0.1, "", "")


def test_path_cost_is_averaged_over_problems_every_row_solved():
    records = [
        _record("coal", 0, True, 1.0),
        _record("coal", 1, True, 5.0),
        _record("GraphDistNet", 0, True, 3.0),
        _record("GraphDistNet", 1, False, 100.0),
    ]
    rows = {r.method: r for r in table2.summarize(records)}
    assert rows["coal"].mean_cost == 1.0 and rows["GraphDistNet"].mean_cost == 3.0
    assert rows["coal"].common == 1
    assert rows["GraphDistNet"].successes == 1 and rows["GraphDistNet"].n == 2


def test_paper_numbers_sit_beside_the_adam_rows_only():
    rows = table2.summarize(
        [
            table2.Record("d", "GraphDistNet", s, 0, True, 2.0, 0.0, 1.0, 0.1, "", "")
            for s in ("ipopt", "adam")
        ]
    )
    ipopt, adam = table2.markdown(rows).splitlines()[2:]
    assert "16.2682" in adam and "16.2682" not in ipopt


def test_missing_weights_skip_a_method_with_the_reason(tmp_path):
    with pytest.raises(gp.InputError, match="no weights"):
        table2.model_factory("ClearanceNet", "fetch", tmp_path)
    with pytest.raises(gp.InputError, match="unknown"):
        table2.model_factory("RRT", "b")


def test_cli_writes_the_table_and_records(tmp_path):
    out = tmp_path / "table2.md"
    result = CliRunner().invoke(
        app,
        ["reproduce", "table2", "--n", "1", "--settings", "b", "--methods", "coal",
         "--solvers", "ipopt", "--out", str(out)],
    )  # fmt: skip
    assert result.exit_code == 0, result.output
    text = out.read_text()
    assert "| b | coal | ipopt | 1/1 |" in text
    (record,) = json.loads(out.with_suffix(".json").read_text())["records"]
    assert record["success"] and record["min_distance"] > 0


def test_update_keeps_the_rows_a_run_does_not_redo(tmp_path):
    out = tmp_path / "table2.md"
    first = table2.Record("b", "coal", "ipopt", 0, True, 1.0, 0.0, 2.0, 0.03, "ok", "")
    table2.write([first, replace(first, solver="adam")], ["DiffCo: none"], "run 1", out)
    redo = replace(first, success=False, time=5.0)
    text = table2.write([redo], [], "run 2", out, update=True)
    assert "| b | coal | ipopt | 0/1 |" in text and "| b | coal | adam | 1/1 |" in text
    assert "`run 1`" in text and "`run 2`" in text and "DiffCo: none" in text
    saved = json.loads(out.with_suffix(".json").read_text())
    assert [r["command"] for r in saved["runs"]] == ["run 1", "run 2"]
    assert len(saved["records"]) == 2
    before = out.read_text()
    assert table2.write([], [], "", out, update=True) == before  # re-render only: no new run
    assert len(json.loads(out.with_suffix(".json").read_text())["runs"]) == 2
    text = table2.write([replace(redo, time=6.0)], [], "run 3", out, update=True)
    assert "`run 2`" not in text and "`run 1`" in text  # run 2's only row was redone
    text = table2.write([redo], [], "run 4", out)  # without update: only this run's rows
    assert "adam" not in text.split("Notes:")[0] and "`run 1`" not in text


def test_cli_rejects_unknown_settings():
    result = CliRunner().invoke(app, ["reproduce", "table2", "--settings", "z"])
    assert result.exit_code != 0
    assert "--settings" in str(result.exception) + result.output


def test_a_narrow_passage_is_seeded_at_the_margin_when_extra_clearance_fails():
    problem = table2.reaching_problems("b", n=10, seed=0)[9]  # passage narrower than 4 cm
    result = gp.plan(problem, collision="coal", seed=9)
    assert result.success, result.reason
    assert "(clearance = margin)" in result.reason
