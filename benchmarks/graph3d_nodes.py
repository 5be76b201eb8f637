"""Robot graph node count vs distance accuracy (GraphDistNet-3D's robot graphs, issue #24).

For each cylinder rim count, the UR5e's link shapes are replaced by the convex hulls of their
graph nodes (:func:`gdnplan.graph3d.shape_points`) and coal's robot–obstacle signed distance of
that robot is compared with the true one (obstacle pairs only) on random configurations among
20 random boxes: the error a graph of that many nodes commits by its geometry alone.

    python benchmarks/graph3d_nodes.py [--configs 300] [--scenes 3]
"""

from __future__ import annotations

import argparse
import dataclasses

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
    p = argparse.ArgumentParser(description=__doc__)
    p.add_argument("--configs", type=int, default=300)
    p.add_argument("--scenes", type=int, default=3)
    a = p.parse_args()
    robot = load_robot3d("ur5e")
    exact = without_self(robot)
    print("| rim points | robot nodes | MAE (mm) | 95 % abs err (mm) | max abs err (mm) |")
    print("|---|---|---|---|---|")
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
        print(
            f"| {rim} | {n} | {e.mean():.2f} | {np.percentile(e, 95):.2f} | {e.max():.2f} |",
            flush=True,
        )


if __name__ == "__main__":
    main()
