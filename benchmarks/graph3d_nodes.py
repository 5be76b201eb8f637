"""Robot graph node count vs distance accuracy (GraphDistNet-3D's robot graphs, issue #24).

For each cylinder rim count, the UR5e's link shapes are replaced by the convex hulls of their
graph nodes (:func:`gdnplan.graph3d.shape_points`) and coal's robot–obstacle signed distance of
that robot is compared with the true one (obstacle pairs only) on random configurations among
20 random boxes: the error a graph of that many nodes commits by its geometry alone.

    python benchmarks/graph3d_nodes.py --threads 1 [--configs 300] [--scenes 3]
"""

from __future__ import annotations

import dataclasses

import common
import numpy as np

from gdnplan.arm3d import Checker3D, Robot3D, Scene3D, load_robot3d, random_boxes
from gdnplan.arm3d.shapes import convex
from gdnplan.graph3d import robot_graph3d, shape_points


def without_self(robot: Robot3D, shapes=None) -> Robot3D:
    return Robot3D(
        robot.name, robot.model, shapes or robot.shapes, np.zeros((0, 2), int), {}, robot.info
    )


def node_robot(robot: Robot3D, rim: int) -> Robot3D:
    shapes = [
        dataclasses.replace(s, shape=convex(shape_points(s.shape, rim), s.name))
        for s in robot.shapes
    ]
    return without_self(robot, shapes)


def main() -> None:
    p = common.parser("graph3d_nodes", __doc__)
    p.add_argument("--configs", type=int, default=300)
    p.add_argument("--scenes", type=int, default=3)
    a = common.parse(p)
    report = common.Report(
        a, "Robot graph nodes vs distance accuracy", common.first_paragraph(__doc__)
    )
    report.text(
        f"UR5e, {a.configs} random configurations in each of {a.scenes} scenes of 20 random "
        "boxes (seeds 1000 …); |coal distance of the node-hull robot − true distance|."
    )
    table = report.table(
        "rim points", "robot nodes", "MAE (mm)", "95 % abs err (mm)", "max abs err (mm)"
    )
    robot = load_robot3d("ur5e")
    exact = without_self(robot)
    for rim in (4, 6, 8, 12, 16):
        approx = node_robot(robot, rim)
        errs = []
        for s in range(a.scenes):
            boxes = random_boxes(robot, 20, seed=1000 + s).obstacles
            q = robot.random_configurations(a.configs, np.random.default_rng(s))
            d = Checker3D(Scene3D(exact, boxes)).evaluate(q).distance
            d_nodes = Checker3D(Scene3D(approx, boxes)).evaluate(q).distance
            errs.append(np.abs(d_nodes - d))
        e = np.concatenate(errs) * 1e3
        n = robot_graph3d(robot, rim).n_nodes
        table.add(rim, n, f"{e.mean():.2f}", f"{np.percentile(e, 95):.2f}", f"{e.max():.2f}")
    report.write()


if __name__ == "__main__":
    main()
