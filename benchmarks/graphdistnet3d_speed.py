"""Time per configuration of GraphDistNet-3D vs coal-3D: distance, and distance + gradient.

The UR5e among 20 random boxes (``random_boxes(robot, 20, seed)``), random configurations
within the joint limits, side by side in one run (:func:`common.time_calls`). coal-3D: the
robot–obstacle signed distance with its broad phase (:class:`gdnplan.arm3d.Checker3D` of the
robot without self pairs), and the full distance with self-collision (``Coal3DModel``).
GraphDistNet-3D: the learned robot–obstacle distance (``learned_distance``, untrained weights of
the default architecture: the time does not depend on the weights) and the DistanceModel's
distance with the exact self-collision beside it. Obstacle features are computed once per scene
before timing (one-way cross edges). The Pinocchio kinematics of the robot graph are timed
alone too. ``--variants`` adds the learned distance + gradient of smaller architectures
(``rim:hidden:layers``: points per cylinder rim, d_h = every MLP width, K), untrained.

    python benchmarks/graphdistnet3d_speed.py --threads 1 [--n 5000] [--repeats 3]
        [--variants 6:16:3,4:16:3]
"""

from __future__ import annotations

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
    model.distance(scene, q[:2])  # builds the scene cache (obstacle features)
    coal_obs, coal_full = Checker3D(bare), Coal3DModel()
    graph = robot_graph3d(robot)
    calls = {
        "coal-3D robot–obstacle distance": lambda: coal_obs.evaluate(q),
        "coal-3D robot–obstacle distance + gradient": lambda: coal_obs.evaluate(q, gradient=True),
        "coal-3D with self-collision: distance + gradient": lambda: coal_full.distance_and_grad(
            scene, q
        ),
        "GraphDistNet-3D learned distance": lambda: model.learned_distance(scene, q),
        "GraphDistNet-3D learned distance + gradient": lambda: model.learned_distance_and_grad(
            scene, q
        ),
        "GraphDistNet-3D + exact self: distance + gradient": lambda: model.distance_and_grad(
            scene, q
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
        small = GraphDistNet3DModel(GraphDistNet3D(config), threads=args.threads)
        small.distance(scene, q[:2])
        nodes = robot_graph3d(robot, rim).n_nodes
        name = f"GraphDistNet-3D {nodes} nodes, d_h = {hidden}, K = {layers}: distance + gradient"
        calls[name] = lambda m=small: m.learned_distance_and_grad(scene, q)
    report.text(
        f"{args.n} configurations, 20 boxes (seed {args.seed}), {graph.n_nodes} robot nodes, "
        f"{len(scene.obstacles) * 8} obstacle nodes; best and median of {args.repeats} rounds."
    )
    times = common.time_calls(calls, repeats=args.repeats)
    base = times["coal-3D robot–obstacle distance + gradient"].best
    table = report.table("what", "best µs / config", "median µs / config", "best / coal d+grad")
    for name, t in times.items():
        t_best, t_median = t.best, t.median
        table.add(
            name,
            f"{1e6 * t_best / args.n:.1f}",
            f"{1e6 * t_median / args.n:.1f}",
            f"{t_best / base:.2f}",
        )
    report.write()


if __name__ == "__main__":
    main()
