"""Time per configuration of GraphDistNet-3D vs coal-3D: distance, and distance + gradient.

The UR5e among 20 random boxes (``random_boxes(robot, 20, seed)``), random configurations
within the joint limits, side by side in one run (:func:`common.time_calls`). coal-3D: the
robot–obstacle signed distance with its broad phase (:class:`gdnplan.arm3d.Checker3D` of the
robot without self pairs), and the full distance with self-collision (``Coal3DModel``).
GraphDistNet-3D: the learned robot–obstacle distance (``learned_distance``, untrained weights of
the default architecture: the time does not depend on the weights) by the compiled pass
(``fused``, the default, :mod:`gdnplan.models.graphdistnet3d.fused3d`) and by torch
(``fused=False``), and the DistanceModel's distance with the exact self-collision beside it.
Obstacle features are computed once per scene before timing (one-way cross edges). The
Pinocchio kinematics of the robot graph are timed alone too. ``--variants`` adds the learned
distance + gradient of smaller architectures (``rim:hidden:layers``: points per cylinder rim,
d_h = every MLP width, K), untrained, both ways. Times are wall (interleaved rounds) and the
thread CPU time of the same calls (every call runs on this thread: on a shared machine the
CPU time is the fairer measure).

    python benchmarks/graphdistnet3d_speed.py --threads 1 [--n 5000] [--repeats 3]
        [--variants 6:16:3,4:16:3]
"""

from __future__ import annotations

import time

import common
import numpy as np
import torch

from gdnplan.arm3d import Checker3D, Coal3DModel, Scene3D, load_robot3d, random_boxes
from gdnplan.arm3d.scene3d import workspace_radius
from gdnplan.data.samples3d import obstacle_robot
from gdnplan.graph3d import robot_graph3d
from gdnplan.models.graphdistnet3d import GraphDistNet3D, GraphDistNet3DConfig, GraphDistNet3DModel


def main() -> None:
    p = common.parser("graphdistnet3d_speed", __doc__)
    p.add_argument("--n", type=int, default=5000, help="configurations")
    p.add_argument("--repeats", type=int, default=3)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--variants", default="6:16:3,4:16:3", help="rim:hidden:layers, comma-separated")
    args = common.parse(p)
    report = common.Report(args, "GraphDistNet-3D vs coal-3D", common.first_paragraph(__doc__))
    robot = load_robot3d("ur5e")
    scene = random_boxes(robot, 20, seed=args.seed)
    bare = Scene3D(obstacle_robot("ur5e"), scene.obstacles)
    q = robot.random_configurations(args.n, np.random.default_rng(args.seed))
    torch.manual_seed(0)
    net = GraphDistNet3D(GraphDistNet3DConfig(scale=workspace_radius(robot)))
    model = GraphDistNet3DModel(net, threads=args.threads)
    reference = GraphDistNet3DModel(net, threads=args.threads, fused=False)
    if not model.fused:
        raise SystemExit("the compiled pass does not serve here (numba missing?)")
    for m in (model, reference):
        m.distance_and_grad(scene, q[:2])  # builds the scene cache (obstacle features)
    coal_obs, coal_full = Checker3D(bare), Coal3DModel()
    graph = robot_graph3d(robot)
    calls = {
        "coal-3D robot–obstacle distance": lambda: coal_obs.evaluate(q),
        "coal-3D robot–obstacle distance + gradient": lambda: coal_obs.evaluate(q, gradient=True),
        "coal-3D with self-collision: distance + gradient": lambda: coal_full.distance_and_grad(
            scene, q
        ),
        "GraphDistNet-3D compiled: learned distance": lambda: model.learned_distance(scene, q),
        "GraphDistNet-3D compiled: learned distance + gradient": (
            lambda: model.learned_distance_and_grad(scene, q)
        ),
        "GraphDistNet-3D compiled + exact self: distance + gradient": (
            lambda: model.distance_and_grad(scene, q)
        ),
        "GraphDistNet-3D torch: learned distance": lambda: reference.learned_distance(scene, q),
        "GraphDistNet-3D torch: learned distance + gradient": (
            lambda: reference.learned_distance_and_grad(scene, q)
        ),
        "robot graph kinematics (Pinocchio) alone": lambda: graph.kinematics(q),
    }
    for variant in filter(None, args.variants.split(",")):
        rim, hidden, layers = (int(x) for x in variant.split(":"))
        config = GraphDistNet3DConfig(
            scale=workspace_radius(robot),
            rim=rim,
            hidden=hidden,
            mlp=(hidden,) * 3,
            readout=(hidden,) * 3,
            layers=layers,
        )
        small_net = GraphDistNet3D(config)
        nodes = robot_graph3d(robot, rim).n_nodes
        for fused in (True, False):
            small = GraphDistNet3DModel(small_net, threads=args.threads, fused=fused)
            small.distance_and_grad(scene, q[:2])
            name = (
                f"GraphDistNet-3D {'compiled' if fused else 'torch'} {nodes} nodes, "
                f"d_h = {hidden}, K = {layers}: learned distance + gradient"
            )
            calls[name] = lambda m=small: m.learned_distance_and_grad(scene, q)
    report.text(
        f"{args.n} configurations, 20 boxes (seed {args.seed}), {graph.n_nodes} robot nodes, "
        f"{len(scene.obstacles) * 8} obstacle nodes; best and median of {args.repeats} rounds."
    )
    cpu: dict[str, list[float]] = {name: [] for name in calls}
    times = common.time_calls(
        {name: _cpu_timed(fn, cpu[name]) for name, fn in calls.items()}, repeats=args.repeats
    )
    key = "coal-3D robot–obstacle distance + gradient"
    base, base_cpu = times[key].best, min(cpu[key][1:])
    table = report.table(
        "what",
        "best µs / config",
        "median µs / config",
        "best CPU µs / config",
        "best / coal d+grad",
        "CPU / coal d+grad CPU",
    )
    for name, t in times.items():
        t_cpu = min(cpu[name][1:])  # the first is the warm-up round
        table.add(
            name,
            f"{1e6 * t.best / args.n:.1f}",
            f"{1e6 * t.median / args.n:.1f}",
            f"{1e6 * t_cpu / args.n:.1f}",
            f"{t.best / base:.2f}",
            f"{t_cpu / base_cpu:.2f}",
        )
    report.write()


def _cpu_timed(fn, out: list[float]):
    """``fn`` that appends its thread CPU time (s) to ``out`` at every call."""

    def timed() -> None:
        start = time.thread_time()
        fn()
        out.append(time.thread_time() - start)

    return timed


if __name__ == "__main__":
    main()
