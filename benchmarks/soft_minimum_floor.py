"""What the node distances give before any training: the soft minimum m of an untrained
``min_readout`` network (its readout MLP starts at zero, so d̂ = scale · m) on a test split.

m = −τ_m log Σ_i exp(−s_i / τ_m) over the signed node distances s_i (robot nodes to the obstacles,
obstacle nodes to the links) is the distance itself between polygons that are apart, so this
reports where the network has something left to learn: MAE and bias per band of coal's f, and
AUC, on ``data/<env>/test`` (``gdnplan generate --env E --split test``).

    python benchmarks/soft_minimum_floor.py --threads 1 a [c …]
"""

from __future__ import annotations

import json

import common
import numpy as np
import torch

from gdnplan.data import load
from gdnplan.models.graphdistnet import GraphDistNet, GraphDistNetConfig
from gdnplan.train import predict, roc_auc, tensors

BANDS = [(-1, -0.05), (-0.05, -0.01), (-0.01, 0), (0, 0.01), (0.01, 0.05), (0.05, 0.2), (0.2, 9)]


def main() -> None:
    p = common.parser("soft_minimum_floor", __doc__)
    p.add_argument("envs", nargs="+")
    args = common.parse(p)
    report = common.Report(args, "The soft minimum alone", common.first_paragraph(__doc__))
    for env in args.envs:
        card = json.loads((common.ROOT / "weights" / f"{env}.json").read_text())["config"]
        config = GraphDistNetConfig.from_dict(card).with_(
            node_distance=True, min_readout=True, two_way=True
        )
        torch.manual_seed(0)
        ds = load(common.ROOT / "data" / env / "test")
        d_hat, _ = predict(GraphDistNet(config), tensors(ds, config), grad=False)
        err = d_hat - ds.d
        report.text(
            f"**{env}**: n {len(err)}, MAE {np.abs(err).mean():.4f} m, "
            f"AUC {roc_auc(ds.d <= 0, -d_hat):.5f}"
        )
        table = report.table("f band (m)", "n", "MAE (m)", "bias (m)")
        for lo, hi in BANDS:
            band = (ds.d >= lo) & (ds.d < hi)
            table.add(
                f"[{lo}, {hi})",
                band.sum(),
                f"{np.abs(err[band]).mean():.4f}",
                f"{err[band].mean():+.4f}",
            )
    report.write()


if __name__ == "__main__":
    main()
