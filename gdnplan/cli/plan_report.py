"""What ``gdnplan plan`` and the fetch commands print: clearance, timing and fetch-stage lines,
and the JSON summary of a plan (:func:`plan_summary`)."""

from __future__ import annotations

import math

import typer

from ..limits import floor_text


def echo_stages(stages, grippers) -> float:
    """Print one line per fetch stage (name, gripper, planned/scripted, verdict, clearance,
    time) and return the stages' total solve time (s); ``grippers``: each stage's gripper."""
    for s, gripper in zip(stages, grippers, strict=True):
        how = "planned" if s.planned else "scripted"
        verdict = "certified" if s.success else f"FAILED ({s.detail})"
        typer.echo(f"{s.name:<10} {gripper:<8} {how:<8} {verdict}; {stage_clearance(s)}, "
                   f"{s.solve_time:.2f} s")  # fmt: skip
    return sum(s.solve_time for s in stages)


def stage_clearance(stage) -> str:
    """The clearance a fetch stage proves: over its whole path, or (the lift) from the row
    its certificate starts at, with the distance before it."""
    start = getattr(stage, "certified_from", 0)
    if not start:
        return clearance_text(stage.min_distance)
    return (
        f"{clearance_text(stage.certified_min_distance)} from waypoint {start} on "
        f"(distance {stage.min_distance:+.4f} m before it)"
    )


def timing_text(traj) -> str:
    """'duration 2.24 s (smooth curve, certified clearance ≥ +0.0206 m)', or the duration with
    the timing's kind ('linear' / 'stop': the certified waypoint polygon)."""
    if traj.kind == "smooth":
        return f"duration {traj.duration:.2f} s (smooth curve, {clearance_text(traj.min_distance)})"
    return f"duration {traj.duration:.2f} s ({traj.kind}, along the certified polygon)"


def clearance_text(lower_bound: float) -> str:
    """'certified clearance ≥ +0.0123 m' (rounded down, :func:`~gdnplan.limits.floor_text`:
    never more than was proven); 'nothing to collide with' for a +inf bound (no obstacles, no
    self-collision pairs), 'clearance not proven' for −inf (or NaN)."""
    if lower_bound == math.inf:
        return "nothing to collide with (no obstacles)"
    if not math.isfinite(lower_bound):
        return "clearance not proven"
    return f"certified clearance ≥ {floor_text(lower_bound)} m"


def json_number(x: float) -> float | None:
    """x as a JSON number; None (null) when not finite (JSON has no infinities)."""
    return float(x) if math.isfinite(x) else None


def plan_summary(result, joint_names: list[str]) -> dict:
    """JSON-ready summary of a Plan (min_distance: the proven lower bound, null if none or
    unbounded — nothing to collide with — which ``success`` tells apart;
    clearance: the clearance its certificate had to prove).

    ``t`` (s) is the time of each row of ``q`` (rad, columns in ``joint_names`` order), and
    ``timing`` its kind (:mod:`gdnplan.timing`); both null when the plan has no trajectory.
    ``timing_min_distance`` (m): the proven clearance of the ``smooth`` curve (planar or 3-D),
    null for the other kinds (they follow the certified polygon).
    """
    traj = result.trajectory
    import numpy as np

    return {
        "success": bool(result.success),
        "joint_names": list(joint_names),
        "q": np.asarray(result.q).tolist(),
        "t": None if traj is None else traj.times.tolist(),
        "duration": None if traj is None else traj.duration,
        "timing": None if traj is None else traj.kind,
        "timing_min_distance": None
        if traj is None or traj.min_distance is None
        else json_number(traj.min_distance),
        "min_distance": json_number(result.min_distance),
        "sampled_min_distance": json_number(result.sampled_min_distance),
        "clearance": float(result.clearance),
        "solve_time": float(result.solve_time),
        "iterations": int(result.iterations),
        "status": result.status,
        "reason": result.reason,
        "path_cost": float(result.path_cost),
        "seed": None if result.seed is None else result.seed.summary(),
        "attempts": int(result.attempts),
    }
