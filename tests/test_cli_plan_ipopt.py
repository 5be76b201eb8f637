"""``gdnplan plan`` with Ipopt options: --json stdout stays one JSON object whatever Ipopt prints,
an out-of-range option is one error line and exit 2 (not Ipopt's option help and exit 3), and
Ctrl-C during a solve exits 130 promptly; in Python the interrupt is a KeyboardInterrupt."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

from gdnplan.trajopt import IpoptConfig, PlanConfig, Problem, SeedConfig, plan

SQUARE = Path(__file__).parent.parent / "problems" / "planar2_square.toml"
CLI = [sys.executable, "-c", "from gdnplan.cli import main; main()"]
SLOW = "bound_push = 1e10"  # in range, but Ipopt then iterates until its caps: a long solve


def problem_file(tmp_path: Path, options: str, extra: str = "") -> Path:
    path = tmp_path / "p.toml"
    path.write_text(f"{SQUARE.read_text()}\n{extra}\n[ipopt.options]\n{options}\n")
    return path


def test_json_stdout_is_one_object_with_ipopts_log_on(tmp_path):
    path = problem_file(tmp_path, "print_level = 5")
    proc = subprocess.run(
        [*CLI, "plan", str(path), "--collision", "coal", "--json", "-q"],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert proc.returncode == 0, proc.stderr
    summary = json.loads(proc.stdout)  # the whole of stdout
    assert summary["success"] is True
    assert "Number of Iterations" in proc.stderr  # Ipopt's log went to stderr instead


@pytest.mark.parametrize(
    "options, words",
    [
        ("print_level = 99", "ipopt.print_level: expected an integer in [0, 12], got 99"),
        ("bound_frac = 5.0", "ipopt.bound_frac: expected a number in (0, 0.5], got 5.0"),
        ('hessian_approximation = "exact"', "ipopt.hessian_approximation: 'exact' is not"),
    ],
)
def test_an_out_of_range_option_is_one_error_line_and_exit_2(tmp_path, options, words):
    path = problem_file(tmp_path, options)
    proc = subprocess.run(
        [*CLI, "plan", str(path), "--collision", "coal", "--json"],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert proc.returncode == 2, proc.stderr
    assert proc.stdout == ""
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error:") and words in lines[0], proc.stderr


def test_ctrl_c_during_a_solve_exits_130_promptly(tmp_path):
    path = problem_file(tmp_path, SLOW, extra="[seed]\ntime_budget = 120.0")
    proc = subprocess.Popen(
        [*CLI, "plan", str(path), "--collision", "coal"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        for line in proc.stderr:  # the stage lines: wait until Ipopt is solving
            if line.startswith("seed:") and "path found" in line:
                break
        time.sleep(0.5)
        sent = time.monotonic()
        proc.send_signal(signal.SIGINT)
        rest = proc.communicate(timeout=30)[1]
    finally:
        proc.kill()
    took = time.monotonic() - sent
    assert proc.returncode == 130, rest
    assert "error: interrupted" in rest
    assert took < 10.0, f"{took:.1f} s from Ctrl-C to exit"


def test_an_interrupt_during_a_solve_is_a_keyboard_interrupt_in_python():
    if signal.getsignal(signal.SIGINT) is not signal.default_int_handler:
        pytest.skip("SIGINT is handled by someone else here")
    problem = Problem.from_toml(SQUARE)
    cfg = PlanConfig(
        SeedConfig(time_budget=120.0), optimizer=IpoptConfig(options={"bound_push": 1e10})
    )
    timer = threading.Timer(1.5, os.kill, (os.getpid(), signal.SIGINT))
    t0 = time.monotonic()
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        plan(problem, collision="coal", solver=cfg)
    timer.join()
    assert time.monotonic() - t0 < 10.0  # not the 120 s budget: stopped at the interrupt
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler  # restored
