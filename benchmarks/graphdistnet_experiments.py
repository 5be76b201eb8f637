"""GraphDistNet experiments side by side: test metrics and d̂ continuity along joint sweeps.

For every ``weights/<name>.safetensors`` given (default: all GraphDistNet weights), on the same
held-out split ``data/<env>/test`` (5 000 samples; ``--split tests`` uses the committed
300-sample files): MAE (m, fraction of reach), AUC (collision ⇔ d ≤ 0), ACD, and along 1-D
sweeps (3 random configurations × every joint, 0.003 rad steps, 200 steps, scene seed 11) the
median and maximum |Δd̂| between consecutive steps.

    .venv/bin/python benchmarks/graphdistnet_experiments.py [b b_faithful ...] [--split tests]
"""

from __future__ import annotations

import argparse
import json
import platform
from pathlib import Path

import numpy as np
import torch

import gdnplan as gp
from gdnplan.data import load, split_dir
from gdnplan.train import evaluate

ROOT = Path(__file__).resolve().parent.parent


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
    p = argparse.ArgumentParser()
    p.add_argument("names", nargs="*")
    p.add_argument("--split", choices=["data", "tests"], default="data")
    a = p.parse_args()
    torch.set_num_threads(1)
    names = a.names or sorted(
        f.stem
        for f in (ROOT / "weights").glob("*.safetensors")
        if json.loads(f.with_suffix(".json").read_text()).get("model") == "graphdistnet"
    )
    print(f"# {platform.processor() or platform.machine()}, torch {torch.__version__}, 1 thread")
    print(
        "| weights | cross | K | epochs | train s | samples/s | MAE m | MAE/reach | AUC | ACD "
        "| median / max sweep jump (cm) |"
    )
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for name in names:
        model = gp.load_model(ROOT / "weights" / f"{name}.safetensors")
        env = model.card["env"]
        small = ROOT / "tests" / "data" / f"{env}_test.npz"
        path = split_dir(env, "test") if a.split == "data" else small
        m = evaluate(model.net, load(path))
        jumps = sweep_jumps(model, gp.make_scene(env, seed=11))
        c, t = model.config, model.card["training"]
        print(
            f"| {name} | {c.cross}{'' if c.cross == 'argmax' else f' k={c.cross_k}'} | {c.layers} "
            f"| {t['epochs']} | {t['seconds']:.0f} | {t['samples_per_s']:.0f} | {m['mae_m']:.4f} "
            f"| {m['mae_reach']:.4f} | {m['auc']:.4f} | {m['acd']:.3f} (n={m['acd_n']}) "
            f"| {100 * np.median(jumps):.2f} / {100 * jumps.max():.2f} |",
            flush=True,
        )


if __name__ == "__main__":
    main()
