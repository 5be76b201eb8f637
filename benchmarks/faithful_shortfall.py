"""Where the paper's network (``weights/<env>_faithful``) loses accuracy: the noise of its
random first-layer partner, and whether its argmax partners find the nearest obstacle.

On the first n held-out samples (seed 1, :func:`gdnplan.metrics.test_set`): MAE and AUC of one
draw of the random first-layer pick (generator seed 0, what Table I uses) and of the mean d̂
over ``--draws`` draws, the spread of d̂ between draws; then, on the first ``--partners``
samples, how often the robot graph's argmax partner of each layer k ≥ 1 lies on the obstacle
nearest to the arm (coal, one obstacle at a time) and the error with and without such a layer.

    python benchmarks/faithful_shortfall.py --threads 1 d [b …]
"""

from __future__ import annotations

import common
import numpy as np
import torch

from gdnplan.distance import signed_distance
from gdnplan.metrics import roc_auc, test_set
from gdnplan.models import load_model
from gdnplan.train import tensors


def predictions(net, t, seed: int) -> np.ndarray:
    """d̂ (n,) of every sample of ``t`` with the first-layer pick of generator ``seed``."""
    gen = torch.Generator().manual_seed(seed)
    out = []
    for s in range(0, len(t), 256):
        robot, obstacles = t.batch(torch.arange(s, min(s + 256, len(t))), "cpu")
        with torch.inference_mode():
            out.append(net(robot, obstacles, gen).double().numpy())
    return np.concatenate(out)


def partner_obstacles(net, t, m: int) -> np.ndarray:
    """(m, K − 1) obstacle node index of the robot graph's argmax partner of layers 1 … K − 1."""
    seen, original = [], net.partners_argmax

    def spy(g, h, k, generator):
        idx = original(g, h, k, generator)
        if h is not None:
            seen.append(idx[:, 0] - g.n_robot)  # every robot node shares this partner
        return idx

    net.partners_argmax = spy
    try:
        robot, obstacles = t.batch(torch.arange(m), "cpu")
        with torch.inference_mode():
            net(robot, obstacles, torch.Generator().manual_seed(0))
    finally:
        net.partners_argmax = original
    return torch.stack(seen, 1).numpy()


def main() -> None:
    p = common.parser("faithful_shortfall", __doc__)
    p.add_argument("envs", nargs="+")
    p.add_argument("--n", type=int, default=5000)
    p.add_argument("--draws", type=int, default=8)
    p.add_argument("--partners", type=int, default=1000)
    args = common.parse(p)
    report = common.Report(
        args, "The faithful network's shortfall", common.first_paragraph(__doc__)
    )
    for env in args.envs:
        model = load_model(common.ROOT / "weights" / f"{env}_faithful.safetensors")
        net = model.net.eval()
        ds = test_set(env, args.n)
        t, f = tensors(ds), ds.d
        draws = np.stack([predictions(net, t, k) for k in range(args.draws)])
        table = report.table("env", "d̂ of", "MAE (m)", "AUC")
        aucs = [roc_auc(-d, f <= 0) for d in draws]
        for name, d in (("one draw (seed 0)", draws[0]), (f"mean of {args.draws}", draws.mean(0))):
            table.add(env, name, f"{np.abs(d - f).mean():.4f}", f"{roc_auc(-d, f <= 0):.4f}")
        spread = draws.std(0)
        report.text(
            f"**{env}** (one random first-layer partner per graph, n {len(f)}): AUC of single "
            f"draws {np.mean(aucs):.4f} ± {np.std(aucs):.4f}; std of d̂ between draws "
            f"{spread.mean():.4f} m, within 5 cm of contact {spread[np.abs(f) < 0.05].mean():.4f} m"
        )
        m = min(args.partners, len(ds))
        node = partner_obstacles(net, t, m)
        hits = np.zeros(node.shape, bool)
        for i in range(m):
            scene = ds.scene(i)
            one = [
                signed_distance(scene.with_obstacles([o]), ds.q[i][None])[0]
                for o in scene.obstacles
            ]
            starts = np.r_[0, np.cumsum(ds.sizes[i])]
            hits[i] = np.searchsorted(starts, node[i], side="right") - 1 == int(np.argmin(one))
        err, any_hit, near = np.abs(draws[0][:m] - f[:m]), hits.any(1), np.abs(f[:m]) < 0.1
        report.text(
            f"**{env}** argmax partner on the nearest obstacle (first {m}): by layer "
            f"{', '.join(f'{h:.3f}' for h in hits.mean(0))}, some layer {any_hit.mean():.3f} "
            f"(chance 1/{ds.sizes.shape[1]}); |error| {err[any_hit].mean():.4f} m with, "
            f"{err[~any_hit].mean():.4f} m without; within 10 cm of contact "
            f"{err[any_hit & near].mean():.4f} vs {err[~any_hit & near].mean():.4f} m"
        )
    report.write()


if __name__ == "__main__":
    main()
