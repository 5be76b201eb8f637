"""``gdnplan fetch --3d``: the 3-D UR5e fetch (every stage planned or scripted, all certified)."""

from __future__ import annotations

import json
from pathlib import Path

import typer

from ..errors import InputError
from .common import parse_vector
from .plan import echo_stages


def parse_placement(text: str | None):
    """``"x,y,yaw"`` (m, m, rad) → a :class:`~gdnplan.arm3d.storage3d.Placement`, or None."""
    if text is None:
        return None
    from ..arm3d.storage3d import check_placement

    values = parse_vector(text, "--placement")
    if len(values) != 3:
        raise InputError(f"--placement: expected x,y,yaw (3 numbers), got {text!r}")
    return check_placement(*values)


def run_fetch3d_command(
    seed: int,
    placement: str | None,
    json_output: bool,
    write_problems: Path | None,
) -> bool:
    """Run the 3-D fetch and print it; True when every stage is certified."""
    from ..arm3d.fetch3d import run_fetch3d
    from ..arm3d.fetch3d_scene import fetch3d

    where = parse_placement(placement)
    if write_problems is not None:
        from ..files import check_output_dir

        check_output_dir(write_problems, "--write-problems")
    fetch = fetch3d(seed, placement=where)
    written: list[Path] = []
    if write_problems is not None:
        from ..arm3d.fetch3d_files import write_stage_problems

        written = write_stage_problems(fetch, write_problems)
    stages = run_fetch3d(fetch=fetch)
    ok = all(s.success for s in stages)
    p = fetch.placement
    if json_output:
        summary = {
            "seed": seed,
            "placement": {"x": p.x, "y": p.y, "yaw": p.yaw},
            "collision": "coal",
            "success": ok,
            "stages": [s.summary() for s in stages],
            "problems": [str(w) for w in written],
        }
        typer.echo(json.dumps(summary))
    else:
        total = echo_stages(stages, [s.gripper for s in stages])
        verdict = "success" if ok else "FAILED"
        where_text = f"storage at x {p.x:.3f} m, y {p.y:.3f} m, yaw {p.yaw:.3f} rad"
        typer.echo(f"fetch 3-D seed {seed} ({where_text}): {verdict}, {total:.1f} s in all")
        for w in written:
            typer.echo(f"wrote {w}")
    return ok
