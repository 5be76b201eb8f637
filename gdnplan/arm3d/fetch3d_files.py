"""Problem files of the 3-D fetch's planned stages, in the 3-D problem-file schema.

``gdnplan fetch --3d --write-problems DIR`` writes ``fetch3d_<stage>.toml`` for every planned
stage (approach, reach_in, bring_out, retreat): an ordinary 3-D problem file
(``docs/problem_file_3d.md``) that ``gdnplan plan`` reads like any other::

    [robot]           name = "ur5e", finger = each finger's opening (m: open, or on the stick)
    [robot.held]      holding stages: the stick, a box, at its pose in the tool frame
    [[scene3d.obstacles]]  the table, the storage's boxes (and the stick, while the gripper
                      is open), each at its world pose
    [start] q, [goal] q    the stage's configurations (6 joint angles, rad)
    [options]         waypoints, margin (m)
    [seed]            the stage's RRT-Connect settings (reach_in, bring_out)

A file is one problem, start → goal. The fetch itself (:func:`gdnplan.arm3d.fetch3d.run_fetch3d`)
plans the two straight-line stages piece by piece between knots on the tool line (each piece's
straight line is usually certified without a solve); the file leaves the planner to find the
whole stage's path, which can take longer where the joint-space line hits the entrance.
"""

from __future__ import annotations

from pathlib import Path

from ..files import check_output_dir, write_text
from .fetch3d import MARGIN, PLANNED, STAGE_SOLVERS, WAYPOINTS
from .fetch3d_scene import OPEN_FINGER, Fetch3D
from .write_file3d import problem_file_text


def stage_file_text(fetch: Fetch3D, stage: str, margin: float = MARGIN) -> str:
    """The TOML text of one planned stage's problem file (module doc)."""
    state, start, goal = PLANNED[stage]
    finger = OPEN_FINGER if state == "open" else fetch.storage.stick_width / 2
    tables = {}
    solver = STAGE_SOLVERS.get(stage)
    if solver is not None:
        tables["seed"] = {"rrt_step": solver.seed.rrt_step, "rrt_time": solver.seed.rrt_time}
    p = fetch.placement
    comment = (
        f"gdnplan 3-D fetch, stage {stage} (fetch seed {fetch.seed}, gripper {state}; storage at\n"
        f"x {p.x:.3f} m, y {p.y:.3f} m, yaw {p.yaw:.3f} rad): the UR5e's six joints, coal\n"
        "distances. Written by gdnplan fetch --3d --write-problems; plan: gdnplan plan FILE"
    )
    return problem_file_text(
        {"name": "ur5e", "finger": finger},
        fetch.scenes[state],
        fetch.q[start],
        fetch.q[goal],
        {"waypoints": WAYPOINTS, "margin": float(margin)},
        tables,
        comment,
    )


def write_stage_problems(fetch: Fetch3D, directory: str | Path) -> list[Path]:
    """Write ``fetch3d_<stage>.toml`` for every planned stage into ``directory`` (created);
    every text is made before the first is written, each through a temporary file renamed
    over its target (:func:`gdnplan.files.write_text`), so nothing is left half written."""
    out = check_output_dir(directory, "--write-problems")
    texts = {stage: stage_file_text(fetch, stage) for stage in PLANNED}
    out.mkdir(parents=True, exist_ok=True)
    return [
        write_text(out / f"fetch3d_{stage}.toml", text, "--write-problems")
        for stage, text in texts.items()
    ]


__all__ = ["stage_file_text", "write_stage_problems"]
