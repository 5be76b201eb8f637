"""Thread CPU seconds per stage of the whole-network pass (models/graphdistnet/fused_net.py):
the compiled stages called one by one from Python, tile by tile, for n random configurations
of one scene (float32, one thread).

    python benchmarks/fused_profile.py [--env e] [--n 5000] [--repeats 3] [--out FILE.md]
"""

from __future__ import annotations

import time
from collections import defaultdict

import common
import numpy as np
import torch

import gdnplan as gp
from gdnplan.assets import default_weights
from gdnplan.models.graphdistnet import fused, fused_net
from gdnplan.models.graphdistnet import fused_net_backward as bw
from gdnplan.models.graphdistnet import fused_net_kernels as fw
from gdnplan.models.graphdistnet.fused_net_distances import points_backward, tile_distances


def profile(packed, x, seconds) -> None:
    """Add each stage's thread CPU seconds over the batch x (B, N_r, 2) to ``seconds``."""
    net, cand = packed.net, packed.candidates
    bsz, n_r, _ = x.shape
    n = net.ring.shape[1]
    layers, h = net.att.shape
    tile = max(1, fused_net.TILE_ROWS // (3 * n))
    dt = x.dtype
    width = net.h0t.shape[0]
    st = fw.new_state(x, net, cand, tile)
    two_way = n > n_r
    g_out = np.zeros((bsz, n_r, 2), dt)

    def timed(name, f, *args):
        t0 = time.thread_time()
        out = f(*args)
        seconds[name] += time.thread_time() - t0
        return out

    for b0 in range(0, bsz, tile):
        xt = x[b0 : b0 + tile]
        t_n = xt.shape[0]
        timed("candidates", fw._candidates, xt, net, st)
        if net.din.shape[1]:
            timed("node/probe distances", tile_distances, xt, net, st.s, st.ds)
        pooled = np.empty((t_n, width), dt)
        for k in range(layers):
            timed("soft weights", fw._soft_weights, net, st, k, t_n, two_way)
            uv, cc = timed("node terms", fw._node_terms, net, st, k, t_n, two_way)
            timed("edge MLP", fw._edge_mlp, net, st, k, t_n, uv, cc)
            timed("readout", fw._readout, net, st, k, t_n, n_r, pooled)
        timed("head", fw._head, net, st, pooled, np.empty(t_n, dt))
        rows = t_n * n
        g = g_out[b0 : b0 + tile]
        gs = np.zeros((t_n, st.s.shape[1]), dt)
        dy = timed("head (bw)", bw._head_backward, net, st, t_n, gs)
        dh = np.zeros((rows, h), dt)
        dlphi = np.zeros((t_n, n, cand), dt)
        dnear = np.zeros((t_n, n, cand), dt)
        dscore = np.zeros(rows, dt)
        for k in range(layers - 1, -1, -1):
            timed("readout (bw)", bw._readout_backward, net, st, k, t_n, n_r, dy, dh)
            duv, dc = timed("edge MLP (bw)", bw._edge_backward, net, st, k, t_n, dh)
            if net.din.shape[1]:
                t0 = time.thread_time()
                gs[:, :n] += (dc @ net.din[k]).reshape(t_n, n)
                seconds["node distances (bw, numpy)"] += time.thread_time() - t0
            dscore[:] = 0
            args = (net, st, k, t_n, two_way, duv, dc, dlphi, dnear, dscore)
            timed("cross (bw)", bw._cross_backward, *args)
            if k:
                t0 = time.thread_time()
                dh = np.dot(duv, net.aht[k])
                seconds["dz (bw, numpy)"] += time.thread_time() - t0
        timed("candidates (bw)", bw._candidates_backward, net, st, t_n, n_r, dlphi, dnear, g)
        if gs.shape[1]:
            timed("points (bw)", points_backward, net, gs, st.ds[:t_n], g)


def main() -> None:
    p = common.parser("fused_profile", __doc__)
    p.add_argument("--env", default="e")
    p.add_argument("--n", type=int, default=5000)
    p.add_argument("--repeats", type=int, default=3)
    args = common.parse(p)
    torch.set_num_threads(1)
    report = common.Report(args, "Whole-pass stage profile", common.first_paragraph(__doc__))
    scene = gp.make_scene(args.env, seed=0)
    q = scene.robot.sample(args.n, seed=0)
    model = gp.load_model(default_weights(scene))
    model.fused = True
    graphs = model._graphs(scene)
    packed = graphs.whole
    nodes, _ = graphs.robot.kinematics(q)
    x = np.ascontiguousarray((nodes - packed.origin) / packed.scale, np.float32)
    d = np.empty(len(x), np.float32)
    g = np.zeros(x.shape, np.float32)
    tile = max(1, fused_net.TILE_ROWS // (3 * packed.net.ring.shape[1]))
    whole = float("inf")
    best: dict[str, float] | None = None
    with fused._serial_blas():
        for _ in range(args.repeats + 1):
            g[:] = 0
            t0 = time.thread_time()
            fw.network(x, packed.net, packed.candidates, d, g, tile)
            whole = min(whole, time.thread_time() - t0)
            seconds: dict[str, float] = defaultdict(float)
            profile(packed, x, seconds)
            if best is None or sum(seconds.values()) < sum(best.values()):
                best = seconds
    report.text(
        f"env {args.env}, n {args.n}, rows {packed.net.ring.shape[1]}, tile {tile}; whole pass "
        f"(d + grad, one call): {whole:.3f} s thread CPU (best of {args.repeats + 1})"
    )
    table = report.table("stage", "thread CPU (s)")
    for name, s in best.items():
        table.add(name, f"{s:.3f}")
    table.add("sum of stages", f"{sum(best.values()):.3f}")
    report.write()


if __name__ == "__main__":
    main()
