"""The 3-D fetch on random storage placements: every stage's success, certified clearance and
time (the acceptance run of issue #23 item 6).

For each fetch seed (default 1 … 8: a random storage and placement each, redrawn until its
configurations exist), the scene and its pose-IK configurations are built (``setup``), then the
six stages run with coal distances and the planner's defaults (:func:`run_fetch3d`). A stage
counts when its coal certificate holds (planned stages: d > 0.01 m on the whole continuous
path; grasp: the stick rests on its shelf; lift: certified from 2 mm up). The planned stages'
paths are re-certified here with :func:`certify_path3d`, independently of the planner.
``--weights W``: the planned stages with learned constraints, GraphDistNet-3D weights trained
on ``ur5e_storage`` (refused before any planning otherwise); the certificates stay coal's.

    python benchmarks/fetch3d.py --threads 1 [--seeds 1-8] [--weights W]
"""

from __future__ import annotations

import time

import common
import numpy as np

from gdnplan.arm3d import certify_path3d
from gdnplan.arm3d.fetch3d import MARGIN, STAGES, run_fetch3d
from gdnplan.arm3d.fetch3d_scene import fetch3d


def seeds_arg(text: str) -> list[int]:
    """'1-8' or '1,3,5' → seeds."""
    if "-" in text:
        lo, hi = (int(v) for v in text.split("-"))
        return list(range(lo, hi + 1))
    return [int(v) for v in text.split(",")]


def main() -> None:
    p = common.parser("fetch3d", __doc__)
    p.add_argument("--seeds", type=seeds_arg, default=list(range(1, 9)), help="fetch seeds")
    p.add_argument("--weights", default=None, help="GraphDistNet-3D weights (ur5e_storage)")
    args = common.parse(p)
    collision = "coal"
    title = "3-D fetch: 8 random storage placements"
    if args.weights is not None:
        from gdnplan.cli.fetch3d import learned_fetch_model

        collision = learned_fetch_model(args.weights)
        title += f", learned constraints ({args.weights})"
    report = common.Report(args, title, __doc__.split("\n\n")[1])
    rows = report.table(
        "seed",
        "placement x, y (m), yaw (rad)",
        "stick (m)",
        "setup (s)",
        *(f"{s} (s)" for s in STAGES),
        "all certified",
        "least clearance (m)",
    )
    totals, certified = {s: [] for s in STAGES}, 0
    for seed in args.seeds:
        t0 = time.perf_counter()
        fetch = fetch3d(seed)
        setup = time.perf_counter() - t0
        stages = run_fetch3d(fetch=fetch, collision=collision)
        again = all(certify_path3d(s.scene, s.q, margin=MARGIN).ok for s in stages if s.planned)
        ok = all(s.success for s in stages) and again
        certified += ok
        for s in stages:
            totals[s.name].append(s.solve_time)
        pl = fetch.placement
        least = min(s.min_distance for s in stages if s.name not in ("grasp", "lift"))
        rows.add(
            seed,
            f"{pl.x:.3f}, {pl.y:.3f}, {pl.yaw:.3f}",
            f"{fetch.storage.stick_length:.3f} × {fetch.storage.stick_width:.3f}",
            f"{setup:.2f}",
            *(f"{s.solve_time:.2f}" + ("" if s.success else " FAILED") for s in stages),
            "yes" if ok else "NO",
            f"{least:.4f}",
        )
    med = report.table("stage", "median time (s)", "max time (s)")
    for s in STAGES:
        med.add(s, f"{np.median(totals[s]):.2f}", f"{np.max(totals[s]):.2f}")
    report.text(
        f"{certified}/{len(args.seeds)} fetches with every stage certified (planned stages "
        f"re-certified with certify_path3d at the margin {MARGIN} m). The least clearance is "
        "over the planned stages' proven bounds."
    )
    report.write()


if __name__ == "__main__":
    main()
