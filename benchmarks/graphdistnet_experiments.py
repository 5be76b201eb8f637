"""GraphDistNet experiments side by side: test metrics and d̂ continuity along joint sweeps.

For every ``weights/<name>.safetensors`` given (default: all GraphDistNet weights), on the same
held-out split ``data/<env>/test`` (5 000 samples, made by ``gdnplan generate --env E --split
test``; ``--split tests`` uses the committed 300-sample files): MAE (m, fraction of reach), AUC
(collision ⇔ d ≤ 0), ACD, and along 1-D sweeps (3 random configurations × every joint, 0.003 rad
steps, 200 steps, scene seed 11) the median and maximum |Δd̂| between consecutive steps; the
training columns come from each weights card.

    python benchmarks/graphdistnet_experiments.py --threads 1 [b b_faithful ...] [--split tests]
"""

from __future__ import annotations

import json

import common
import numpy as np

import gdnplan as gp
from gdnplan.data import load, split_dir
from gdnplan.train import evaluate

WEIGHTS = common.ROOT / "weights"


def sweep_jumps(model, scene: gp.Scene, n_configs: int = 3, steps: int = 200) -> np.ndarray:
    """All |Δd̂| (m) between consecutive 0.003 rad steps of 1-D joint sweeps."""
    robot = scene.robot
    jumps = []
    for q0 in robot.sample(n_configs, seed=7):
        for j in range(robot.dof):
            q = np.repeat(q0[None], steps, 0)
            sweep = q0[j] - 0.3 + 0.003 * np.arange(steps)
            q[:, j] = np.clip(sweep, robot.lower[j], robot.upper[j])
            jumps.append(np.abs(np.diff(model.distance(scene, q))))
    return np.concatenate(jumps)


def main() -> None:
    p = common.parser("graphdistnet_experiments", __doc__)
    p.add_argument("names", nargs="*")
    p.add_argument("--split", choices=["data", "tests"], default="data")
    args = common.parse(p)
    names = args.names or sorted(
        f.stem
        for f in WEIGHTS.glob("*.safetensors")
        if json.loads(f.with_suffix(".json").read_text()).get("model") == "graphdistnet"
    )
    report = common.Report(args, "GraphDistNet experiments", common.first_paragraph(__doc__))
    report.text(f"Test split: {args.split} (data: 5 000 samples; tests: 300).")
    table = report.table(
        "weights",
        "cross",
        "K",
        "epochs",
        "train s",
        "samples/s",
        "MAE m",
        "MAE/reach",
        "AUC",
        "ACD",
        "median / max sweep jump (cm)",
    )
    for name in names:
        model = gp.load_model(WEIGHTS / f"{name}.safetensors")
        env = model.card["env"]
        small = common.ROOT / "tests" / "data" / f"{env}_test.npz"
        m = evaluate(model.net, load(split_dir(env, "test") if args.split == "data" else small))
        jumps = sweep_jumps(model, gp.make_scene(env, seed=11))
        c, t = model.config, model.card["training"]
        table.add(
            name,
            c.cross if c.cross == "argmax" else f"{c.cross} k={c.cross_k}",
            c.layers,
            t["epochs"],
            f"{t['seconds']:.0f}",
            f"{t['samples_per_s']:.0f}",
            f"{m['mae_m']:.4f}",
            f"{m['mae_reach']:.4f}",
            f"{m['auc']:.4f}",
            f"{m['acd']:.3f} (n={m['acd_n']})",
            f"{100 * np.median(jumps):.2f} / {100 * jumps.max():.2f}",
        )
    report.write()


if __name__ == "__main__":
    main()
