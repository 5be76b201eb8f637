"""coal's relative tolerance applies to the distance of a pair's cores (a capsule's segment, a
sphere's centre), so the certificate's slack must grow with the swept radii: a large capsule
obstacle made coal overestimate by 14 times the old slack τ (1 + d), and a configuration was
certified at a margin its exact distance did not keep."""

from __future__ import annotations

import coal
import numpy as np
from hypothesis import example, given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from gdnplan.arm3d import Scene3D, load_robot3d
from gdnplan.arm3d.ccd3d import certify_path3d
from gdnplan.arm3d.fk3d import shape_placements_batch
from gdnplan.arm3d.narrow3d import swept_radius
from gdnplan.arm3d.scene3d import capsule_obstacle, sphere_obstacle
from gdnplan.ccd import COAL_SLACK, proven_distance

# the crafted case: a capsule of radius 50 m, 1.39 m long, 5.08 cm from the UR5e
Q = [2.40538311, 0.02411432, -1.76073328, -2.27589831, 1.33974801, -0.86675284]
CENTER = [-27.99669579, 35.98414613, 22.27209915]
ROTVEC = [-0.17627273114654857, 0.7087064094690936, -1.046194141173859]  # the capsule's (rad)


def _golden_min(f, a: float, b: float, iterations: int = 200) -> float:
    """min of a convex function f on [a, b] by golden-section search (exact to ~1e-15 m)."""
    g = (np.sqrt(5) - 1) / 2
    c, d = b - g * (b - a), a + g * (b - a)
    for _ in range(iterations):
        if f(c) < f(d):
            b, d = d, c
            c = b - g * (b - a)
        else:
            a, c = c, d
            d = a + g * (b - a)
    return min(f(a), f(b), f((a + b) / 2))


def _point_distance(shape, p: np.ndarray) -> float:
    """Exact distance (m) of a point p (3,) in the shape's frame to a solid cylinder or box."""
    if isinstance(shape, coal.Cylinder):
        rho = np.hypot(p[0], p[1])
        return float(np.hypot(max(rho - shape.radius, 0.0), max(abs(p[2]) - shape.halfLength, 0)))
    return float(np.linalg.norm(np.maximum(np.abs(p) - np.asarray(shape.halfSide), 0.0)))


def exact_capsule_distance(robot, q, radius, length, center, rot) -> float:
    """Exact distance (m) of the robot's shapes (cylinders, boxes) at q to a capsule: the
    distance of a convex shape to the capsule's segment is convex along it (golden section),
    less the radius; an independent computation, no GJK."""
    tf = shape_placements_batch(robot, np.asarray(q, float)[None])[0]
    axis, best = rot[:, 2], np.inf
    for s, t in zip(robot.shapes, tf, strict=True):

        def along(x, s=s, t=t):
            return _point_distance(s.shape, t[:3, :3].T @ (center + axis * x - t[:3, 3]))

        best = min(best, _golden_min(along, -length / 2, length / 2))
    return best - radius


@given(
    q=st.lists(st.floats(-np.pi, np.pi), min_size=6, max_size=6),
    radius=st.floats(0.01, 60.0),
    length=st.floats(0.01, 2.0),
    rotvec=st.lists(st.floats(-2.0, 2.0), min_size=3, max_size=3),
    gap=st.floats(0.25, 0.6),
    shape=st.integers(0, 12),
)
@example(q=Q, radius=50.0, length=1.392867734739336, rotvec=ROTVEC, gap=None, shape=None)
@settings(max_examples=15, deadline=None)
def test_a_configuration_is_never_certified_above_its_exact_capsule_distance(
    q, radius, length, rotvec, gap, shape
):
    """A configuration (a zero-length path) is never certified at a margin its exact distance
    to a capsule obstacle does not exceed, whatever the capsule's radius (the old slack
    certified the example 15 μm above its exact distance)."""
    robot = load_robot3d("ur5e")
    q, rot = np.array(q), Rotation.from_rotvec(rotvec).as_matrix()
    if gap is None:
        center = np.array(CENTER)
    else:  # the capsule's end ``gap`` beyond a shape's frame, axis pointing away from it
        origin = shape_placements_batch(robot, q[None])[0, shape, :3, 3]
        out = rot[:, 2] / np.linalg.norm(rot[:, 2])
        center = origin + out * (radius + gap + length / 2)
    scene = Scene3D(robot, [capsule_obstacle(radius, length, center, rot, "pillar")])
    exact = exact_capsule_distance(robot, q, radius, length, center, rot)
    if exact >= 0:  # the path's exact clearance is at most ``exact``: no proof above it
        assert not certify_path3d(scene, np.stack([q, q]), margin=exact).ok


def test_swept_radii_are_sphere_and_capsule_radii():
    assert swept_radius(coal.Capsule(0.3, 1.0)) == 0.3
    assert swept_radius(coal.Sphere(2.0)) == 2.0
    assert swept_radius(coal.Cylinder(0.3, 1.0)) == 0.0
    assert swept_radius(coal.Box(1.0, 1.0, 1.0)) == 0.0


@given(radius=st.floats(0.5, 60.0), gap=st.floats(0.001, 0.2), seed=st.integers(0, 2**16))
@settings(max_examples=30, deadline=None)
def test_proven_distance_with_the_swept_radius_covers_coal_on_spheres(radius, gap, seed):
    """A sphere obstacle against a box (an exact point–box distance): the slack with the
    sphere's radius covers coal's error."""
    rng = np.random.default_rng(seed)
    half = rng.uniform(0.02, 0.3, 3)
    rot = Rotation.random(random_state=seed).as_matrix()
    u = rng.normal(size=3)
    u /= np.linalg.norm(u)
    corner = rot @ (np.sign(rot.T @ u) * half)
    center = corner + u * (radius + gap)
    obstacle = sphere_obstacle(radius, center)
    res = coal.DistanceResult()
    req = coal.DistanceRequest()
    d = coal.distance(
        coal.Box(*(2 * half)), coal.Transform3s(rot, np.zeros(3)), obstacle.shape,
        obstacle.pose, req, res,
    )  # fmt: skip
    exact = np.linalg.norm(np.maximum(np.abs(rot.T @ center) - half, 0.0)) - radius
    assert proven_distance(np.array([d]), swept_radius(obstacle.shape))[0] <= exact
    assert d - exact <= COAL_SLACK * (1 + d + radius)
