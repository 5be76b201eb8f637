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


NOT_STORAGE = (
    "--collision graphdistnet: the 3-D fetch needs GraphDistNet-3D weights trained on the storage "
    "and the fetch's gripper and held stick (env ur5e_storage; the shipped "
    "ur5e_boxes3d_preliminary refuse them); give such --weights (the shipped "
    "ur5e_storage3d: --weights ur5e_storage3d) or use --collision coal"
)


def learned_fetch_model(weights: str | None):
    """The GraphDistNet-3D model of ``weights`` for the fetch: InputError (:data:`NOT_STORAGE`)
    without weights or for weights whose card is not of ``ur5e_storage``."""
    if weights is None:
        raise InputError(NOT_STORAGE)
    from ..models import load_model

    model = load_model(weights)
    env = getattr(model, "card", {}).get("env")
    if env != "ur5e_storage":
        raise InputError(f"{NOT_STORAGE} (these weights: env {env!r})")
    return model


def run_fetch3d_command(
    seed: int,
    placement: str | None,
    json_output: bool,
    write_problems: Path | None,
    collision: str = "coal",
    weights: str | None = None,
) -> bool:
    """Run the 3-D fetch and print it; True when every stage is certified. ``collision``
    "graphdistnet" plans with GraphDistNet-3D ``weights``, refused (one InputError, before
    any planning) unless the weights know the storage and both fetch scenes."""
    from ..arm3d.fetch3d import run_fetch3d
    from ..arm3d.fetch3d_scene import fetch3d

    where = parse_placement(placement)
    model = "coal"
    if collision == "graphdistnet":
        model = learned_fetch_model(weights)
    elif weights is not None:
        raise InputError("--weights: only --collision graphdistnet loads weights")
    if write_problems is not None:
        from ..files import check_output_dir

        check_output_dir(write_problems, "--write-problems")
    fetch = fetch3d(seed, placement=where)
    written: list[Path] = []
    if write_problems is not None:
        from ..arm3d.fetch3d_files import write_stage_problems

        written = write_stage_problems(fetch, write_problems)
    try:
        stages = run_fetch3d(fetch=fetch, collision=model)
    except InputError as e:
        if collision != "graphdistnet":
            raise
        raise InputError(f"{NOT_STORAGE} ({e})") from e
    ok = all(s.success for s in stages)
    p = fetch.placement
    if json_output:
        summary = {
            "seed": seed,
            "placement": {"x": p.x, "y": p.y, "yaw": p.yaw},
            "collision": collision,
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
