"""Plan around an obstacle known only as a point cloud (a depth sensor's scan).

python examples/05_point_cloud.py [OUT_DIR]   (default: a new temporary folder)

1. A synthetic scan: points on the robot-facing side and the top of a wall 0.5 m in front of a
   UR5e, with 2 mm of sensor noise, saved as a text file of ``x y z`` lines.
2. A 3-D problem file whose obstacle is ``type = "cloud"`` with ``file = "…"`` and a voxel
   ``resolution``: the points become a coal octree (a superset of the points), which the
   planner's distances and the certificate use.
3. ``gdnplan plan`` on that file (here from Python): the plan is certified against the octree,
   and the distance from the robot to the raw points along the path is at least the proven
   bound.

The shipped ``problems/ur5e_cloud3d.toml`` and its scan were written by this script
(``python examples/05_point_cloud.py gdnplan/shipped/problems``).
"""

import sys
import tempfile
from pathlib import Path

import coal
import numpy as np

import gdnplan as gp

START = [-0.53, 2.182, -1.654, 1.063, -0.595, -1.476]  # rad; the straight line hits the wall
GOAL = [1.281, -1.205, -0.805, 1.667, -0.03, 1.784]
SCAN = "ur5e_cloud3d_scan.xyz"


def wall_scan(n: int = 500, seed: int = 0) -> np.ndarray:
    """(1.1 n, 3) points (m) on the front (x = 0.48 m) and top (z = 0.6 m) of a 0.04 × 0.7 ×
    0.6 m wall, with Gaussian noise of 2 mm, rounded to 0.1 mm."""
    rng = np.random.default_rng(seed)
    front = np.c_[np.full(n, 0.48), rng.uniform(-0.35, 0.35, n), rng.uniform(0.0, 0.6, n)]
    k = n // 10
    top = np.c_[rng.uniform(0.48, 0.52, k), rng.uniform(-0.35, 0.35, k), np.full(k, 0.6)]
    pts = np.r_[front, top]
    return np.round(pts + rng.normal(0.0, 0.002, pts.shape), 4)


def problem_text(scan_file: str) -> str:
    """The 3-D problem file naming the scan (see docs/problem_file_3d.md)."""
    return f"""# The UR5e and a wall known only as a point cloud: a synthetic depth scan,
# {scan_file}. The points become a coal octree of 3 cm voxels, a superset of the
# points: the planner and the certificate use it. Written by examples/05_point_cloud.py.
# Schema: docs/problem_file_3d.md.

[robot]
name = "ur5e"

[[scene3d.obstacles]]
type = "cloud"
name = "wall_scan"
file = "{scan_file}"
resolution = 0.03

[start]
q = {START}

[goal]
q = {GOAL}

[options]
waypoints = 20
margin = 0.02
lower = [-3.1415, -3.1415, -3.1415, -3.1415, -3.1415, -3.1415]
upper = [3.1415, 3.1415, 3.1415, 3.1415, 3.1415, 3.1415]
"""


def distance_to_points(scene, q: np.ndarray, points: np.ndarray) -> float:
    """Smallest distance (m) from the robot's link shapes to the raw points over the
    configurations q (T, dof): each point as a coal sphere of radius 0."""
    robot = scene.robot
    req, best = coal.DistanceRequest(), np.inf
    dots = [coal.Transform3s(np.eye(3), p) for p in points]
    dot = coal.Sphere(1e-9)
    for qt in q:
        for shape, tf in zip(robot.shapes, robot.shape_placements(qt), strict=True):
            pose = coal.Transform3s(tf[:3, :3], tf[:3, 3])
            for where in dots:
                res = coal.DistanceResult()
                best = min(best, coal.distance(shape.shape, pose, dot, where, req, res))
    return float(best)


def main(out_dir: Path) -> None:
    out_dir.mkdir(parents=True, exist_ok=True)
    points = wall_scan()
    np.savetxt(out_dir / SCAN, points, fmt="%.4f", header="x y z (m): a synthetic wall scan")
    (out_dir / "ur5e_cloud3d.toml").write_text(problem_text(SCAN))
    problem = gp.Problem.from_toml(out_dir / "ur5e_cloud3d.toml")
    result = gp.plan(problem)
    print(
        f"{len(points)} points: certified {result.success}, proven clearance ≥ "
        f"{result.min_distance:.4f} m (margin {problem.margin} m), {result.solve_time:.1f} s"
    )
    if result.success:
        raw = distance_to_points(problem.scene, result.q, points)
        print(f"distance to the raw points at the waypoints: {raw:.4f} m")


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else Path(tempfile.mkdtemp(prefix="cloud_")))
