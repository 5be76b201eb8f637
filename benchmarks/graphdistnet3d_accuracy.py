"""Accuracy of GraphDistNet-3D and a ClearanceNet-style MLP against coal on hidden-seed scenes.

UR5e among 20 random boxes (``ur5e_boxes``): MAE (m and fraction of reach), AUC of the
collision classifier d̂ ≤ 0 vs f ≤ 0, ACD = mean (1 − cos(∂d̂/∂q, ∂f/∂q)) against coal's
robot–obstacle labels of a split generated with a seed no training saw (``--hidden``, e.g.
``gdnplan generate --env ur5e_boxes --seed 7``). GraphDistNet-3D: the best state of a training
run's checkpoint (``--run-dir``); the MLP (:mod:`gdnplan.models.clearancenet3d`) is trained here
on the first ``--mlp-n`` training samples for ``--mlp-seconds``. Also the largest change of
GraphDistNet-3D's d̂ per 0.003 rad joint step along random sweeps (acceptance: ≤ 1 cm).

    python benchmarks/graphdistnet3d_accuracy.py --threads 1 --run-dir RUN --train DIR \\
        --hidden DIR [--n 5000] [--mlp-n 50000] [--mlp-seconds 300]
"""

from __future__ import annotations

from pathlib import Path

import common
import numpy as np
import torch

from gdnplan.arm3d import load_robot3d, random_boxes
from gdnplan.models.graphdistnet3d import GraphDistNet3D, GraphDistNet3DConfig, GraphDistNet3DModel
from gdnplan.models.weights import read_card
from gdnplan.train.checkpoint import load_checkpoint
from gdnplan.train.clearancenet3d import (
    evaluate_clearancenet3d,
    load_arrays,
    train_clearancenet3d,
)
from gdnplan.train.graphdistnet3d import evaluate3d


def best_network(run_dir: Path) -> tuple[GraphDistNet3D, dict]:
    ckpt = run_dir / "checkpoint.safetensors"
    card = read_card(ckpt, "checkpoint")
    net = GraphDistNet3D(GraphDistNet3DConfig.from_dict(card["settings"]["network"]))
    state = load_checkpoint(ckpt, net, torch.optim.Adam(net.parameters()))
    if state.get("best_state"):
        net.load_state_dict(state["best_state"])
    return net.eval(), state


def sweep_step(net: GraphDistNet3D, sweeps: int = 5, steps: int = 100) -> float:
    """Largest |Δd̂| (m) per step of ≤ 0.003 rad per joint along random sweeps."""
    robot = load_robot3d("ur5e")
    model = GraphDistNet3DModel(net, self_collision=False)
    rng = np.random.default_rng(0)
    worst = 0.0
    for s in range(sweeps):
        scene = random_boxes(robot, 20, seed=900 + s)
        q0 = robot.random_configurations(1, rng)[0]
        path = q0 + np.arange(steps)[:, None] * rng.uniform(-0.003, 0.003, robot.dof)
        worst = max(worst, float(np.abs(np.diff(model.learned_distance(scene, path))).max()))
    return worst


def main() -> None:
    p = common.parser("graphdistnet3d_accuracy", __doc__)
    p.add_argument("--run-dir", type=Path, required=True)
    p.add_argument("--train", type=Path, required=True)
    p.add_argument("--hidden", type=Path, required=True)
    p.add_argument("--n", type=int, default=5000)
    p.add_argument("--mlp-n", type=int, default=50_000)
    p.add_argument("--mlp-seconds", type=float, default=300.0)
    args = common.parse(p)
    report = common.Report(args, "GraphDistNet-3D accuracy", common.first_paragraph(__doc__))
    net, state = best_network(args.run_dir)
    init = state["settings"].get("init")
    report.text(
        f"GraphDistNet-3D: {args.run_dir}"
        + (f" (started from the weights {init})" if init else "")
        + f", {state['samples']} training samples seen in this run "
        f"({state['seconds']:.0f} s of training, epoch {state['epoch']}), best validation MAE "
        f"{state['best']:.4f} m. Hidden split: {args.hidden}, first {args.n} samples."
    )
    table = report.table("model", "n", "MAE (m)", "MAE / reach", "AUC", "ACD", "collisions")
    g = evaluate3d(net, args.hidden, args.n)
    hidden = load_arrays(args.hidden, args.n)
    mlp, summary = train_clearancenet3d(
        load_arrays(args.train, args.mlp_n), net.config.scale, args.mlp_seconds
    )
    c = evaluate_clearancenet3d(mlp, hidden)
    for name, m in (
        ("GraphDistNet-3D", g),
        (f"ClearanceNet-style MLP ({summary['epochs']} epochs on {summary['n']})", c),
    ):
        table.add(
            name,
            m["n"],
            f"{m['mae_m']:.4f}",
            f"{m['mae_reach']:.4f}",
            f"{m['auc']:.4f}",
            f"{m['acd']:.3f}",
            f"{m['collision_fraction']:.0%}",
        )
    report.text(
        "GraphDistNet-3D largest |Δd̂| per step of ≤ 0.003 rad per joint along 5 sweeps of "
        f"100 steps: {1e3 * sweep_step(net):.3f} mm."
    )
    report.write()


if __name__ == "__main__":
    main()
