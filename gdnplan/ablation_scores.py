"""The ablation's columns of one trained step (:mod:`gdnplan.ablation`'s module docstring):
the test-split figures of its card, d̂ + ∇ time, sweep continuity and Table II with Ipopt."""

from __future__ import annotations

import functools
import json
import time
from pathlib import Path

import numpy as np

from .ablation_steps import TABLE2_SETTINGS, Settings
from .train import git_sha

__all__ = ["grad_time", "loaded_code", "score", "sweep_max", "table2_ipopt", "timing"]


def sweep_max(model, scene, sweeps: int = 3, steps: int = 200) -> float:
    """Largest |Δd̂| (m) between consecutive 0.003 rad steps of sweeps of every joint."""
    robot = scene.robot
    worst = 0.0
    for q0 in robot.sample(sweeps, seed=7):
        for j in range(robot.dof):
            q = np.repeat(q0[None], steps, 0)
            q[:, j] = np.clip(
                q0[j] - 0.3 + 0.003 * np.arange(steps), robot.lower[j], robot.upper[j]
            )
            worst = max(worst, float(np.abs(np.diff(model.distance(scene, q))).max()))
    return worst


def grad_time(model, scene, batch: int) -> float:
    """CPU seconds of this process per configuration of d̂ and ∂d̂/∂q over one batch (fastest
    of 5; the model on one thread, so the work, however busy the shared machine)."""
    q = scene.robot.sample(batch, seed=3)
    model.distance_and_grad(scene, q[:2])  # scene cache, warm-up
    best = np.inf
    for _ in range(5):
        start = time.process_time()
        model.distance_and_grad(scene, q)
        best = min(best, time.process_time() - start)
    return best / batch


def table2_ipopt(model, setting: str, n: int) -> tuple[int, float, float]:
    """(certified successes, median wall time s, median CPU time s) of Ipopt with ``model`` on
    Table II's ``setting`` problems 0 … n − 1; the CPU time is the process's (the work, however
    busy the shared machine)."""
    from .table2 import reaching_problems
    from .trajopt import PlanConfig, plan
    from .trajopt.config import with_optimizer

    config = with_optimizer(PlanConfig(), "ipopt")
    ok, wall, cpu = 0, [], []
    for i, p in enumerate(reaching_problems(setting, n)):
        start = time.process_time()
        r = plan(p, collision=model, solver=config, seed=i)
        cpu.append(time.process_time() - start)
        ok, wall = ok + bool(r.success), [*wall, r.solve_time]
    return ok, float(np.median(wall)), float(np.median(cpu))


def score(weights: Path, env: str, s: Settings) -> dict:
    """The ablation's columns of one trained step (module docstring)."""
    from .models import load_model
    from .scene import make_scene

    model = load_model(weights, threads=1)
    card = json.loads(weights.with_suffix(".json").read_text())
    test, scene = card["test"], make_scene(env, seed=11)
    out = {
        "mae": test["mae_m"], "auc": test["auc"], "acd": test["acd"], "n_test": test["n"],
        "seconds": card["training"]["seconds"], "epochs": card["training"]["epochs"],
        "sweep_max": sweep_max(model, scene, s.sweeps, s.sweep_steps),
    } | timing(model, env, s)  # fmt: skip
    if s.table2 and env in TABLE2_SETTINGS:
        out["t2_success"], out["t2_median"], out["t2_cpu"] = table2_ipopt(model, env, s.table2)
        out["t2_n"], out["t2_git"] = s.table2, loaded_code()  # the planner that solved them
    return out


@functools.cache
def loaded_code() -> str:
    """The commit checked out when this process first asked (its run's start): the code it
    loaded, not a commit made while it ran (:func:`~.train.git_sha` at the time of asking)."""
    return git_sha()


def timing(model, env: str, s: Settings) -> dict:
    """The d̂+∇ column of one trained step's loaded ``model`` (:func:`grad_time`) and the code
    that measured it (``time_git``: the inference kernels change under kept steps;
    ``--retime`` measures again)."""
    from .scene import make_scene

    return {"grad_time": grad_time(model, make_scene(env, seed=11), s.timing_batch),
            "time_git": loaded_code()}  # fmt: skip
