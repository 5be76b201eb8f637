"""What the node distances give before any training: the soft minimum m of an untrained
``min_readout`` network (its readout MLP starts at zero, so d̂ = scale · m) on a test split.

m = −τ_m log Σ_i exp(−s_i / τ_m) over the signed node distances s_i (robot nodes to the obstacles,
obstacle nodes to the links) is the distance itself between polygons that are apart, so this
prints where the network has something left to learn: MAE and bias per band of coal's f, and AUC.

    .venv/bin/python benchmarks/soft_minimum_floor.py a [c …]
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np
import torch

from gdnplan.data import load
from gdnplan.models.graphdistnet import GraphDistNet, GraphDistNetConfig
from gdnplan.train import predict, roc_auc, tensors

ROOT = Path(__file__).resolve().parent.parent
BANDS = [(-1, -0.05), (-0.05, -0.01), (-0.01, 0), (0, 0.01), (0.01, 0.05), (0.05, 0.2), (0.2, 9)]


def main() -> None:
    p = argparse.ArgumentParser()
    p.add_argument("envs", nargs="+")
    torch.set_num_threads(1)
    for env in p.parse_args().envs:
        card = json.loads((ROOT / "weights" / f"{env}.json").read_text())["config"]
        config = GraphDistNetConfig.from_dict(card).with_(
            node_distance=True, min_readout=True, two_way=True
        )
        torch.manual_seed(0)
        ds = load(ROOT / "data" / env / "test")
        d_hat, _ = predict(GraphDistNet(config), tensors(ds, config), grad=False)
        err = d_hat - ds.d
        print(
            f"{env}: n {len(err)}, MAE {np.abs(err).mean():.4f} m, AUC "
            f"{roc_auc(ds.d <= 0, -d_hat):.5f}"
        )
        for lo, hi in BANDS:
            band = (ds.d >= lo) & (ds.d < hi)
            print(
                f"  f in [{lo}, {hi}) m: n {band.sum()}, MAE {np.abs(err[band]).mean():.4f}, "
                f"bias {err[band].mean():+.4f}"
            )


if __name__ == "__main__":
    main()
