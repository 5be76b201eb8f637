"""Shape and pose validation of gdnplan.arm3d: bad geometry never reaches coal (which crashes)."""

from __future__ import annotations

import logging

import coal
import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from gdnplan.arm3d import box_obstacle, mesh_obstacle
from gdnplan.arm3d.shapes import (
    as_pose,
    as_rotation,
    box,
    convex,
    is_convex_mesh,
    load_mesh,
    mesh_hull,
)
from gdnplan.errors import InputError, UnknownNameError

CUBE = np.array(np.meshgrid([-1, 1], [-1, 1], [-1, 1])).reshape(3, -1).T * 0.1


def coal_distance(a, tf_a, b, tf_b) -> float:
    req = coal.DistanceRequest()
    req.enable_signed_distance = True
    return coal.distance(a, tf_a, b, tf_b, req, coal.DistanceResult())


def write_stl(path, vertices, faces) -> None:
    """An ASCII STL of triangles (index triples into vertices)."""
    lines = ["solid t"]
    for f in faces:
        a, b, c = (vertices[i] for i in f)
        n = np.cross(b - a, c - a)
        n = n / np.linalg.norm(n)
        lines += [f"facet normal {n[0]} {n[1]} {n[2]}", "outer loop"]
        lines += [f"vertex {p[0]} {p[1]} {p[2]}" for p in (a, b, c)]
        lines += ["endloop", "endfacet"]
    path.write_text("\n".join([*lines, "endsolid t"]) + "\n")


def dented_cube(depth: float):
    """A cube of side 0.2 whose +z face is four triangles to a vertex pushed ``depth`` inward."""
    v = np.vstack([CUBE, [[0.0, 0.0, 0.1 - depth]]])
    idx = {tuple(np.sign(p).astype(int)): i for i, p in enumerate(CUBE)}

    def quad(a, b, c, d):
        return [(idx[a], idx[b], idx[c]), (idx[a], idx[c], idx[d])]

    faces = quad((-1, -1, -1), (-1, 1, -1), (1, 1, -1), (1, -1, -1))
    faces += quad((-1, -1, -1), (1, -1, -1), (1, -1, 1), (-1, -1, 1))
    faces += quad((1, -1, -1), (1, 1, -1), (1, 1, 1), (1, -1, 1))
    faces += quad((1, 1, -1), (-1, 1, -1), (-1, 1, 1), (1, 1, 1))
    faces += quad((-1, 1, -1), (-1, -1, -1), (-1, -1, 1), (-1, 1, 1))
    top = [(-1, -1, 1), (1, -1, 1), (1, 1, 1), (-1, 1, 1)]
    faces += [(idx[top[k]], idx[top[(k + 1) % 4]], 8) for k in range(4)]
    return v, faces


@pytest.mark.parametrize(
    "points, match",
    [
        (np.c_[np.random.default_rng(0).normal(size=(50, 2)), np.zeros(50)], "flat"),
        (np.random.default_rng(0).normal(size=(50, 3)) * [1, 1, 1e-12], "flat"),
        (np.random.default_rng(0).normal(size=(50, 3)) * [1, 1, 1e-6], "flat"),
        (np.random.default_rng(0).normal(size=(50, 3)) * 1e9, "beyond"),
        (np.full((10, 3), np.nan), "NaN"),
        (np.zeros((3, 3)), "4 ≤ k"),
        (np.outer(np.linspace(0, 1, 20), [1.0, 2.0, 3.0]), "flat"),
    ],
)
def test_bad_point_sets_raise_one_line_input_errors_not_segfaults(points, match):
    with pytest.raises(InputError, match=match) as e:
        convex(points, "part")
    assert "\n" not in str(e.value) and str(e.value).startswith("part")


def test_a_thin_but_valid_plate_is_accepted_and_measured_by_coal():
    plate = convex(CUBE * [5, 5, 0.01], "plate")  # 1 m × 1 m × 2 mm
    d = coal_distance(plate, coal.Transform3s(), coal.Sphere(0.1), as_pose((0, 0, 0.5)))
    assert d == pytest.approx(0.5 - 0.001 - 0.1, abs=1e-6)


@pytest.mark.parametrize(
    "size", [(0.1, 0.1, 0.0), (0.1, np.nan, 0.1), (0.1, 1e9, 0.1), (0.1, 0.1), (True, 1, 1)]
)
def test_bad_box_sizes_are_input_errors(size):
    with pytest.raises(InputError, match="size"):
        box(size)


@given(st.integers(0, 10_000))
@settings(max_examples=30, deadline=None)
def test_quaternion_and_matrix_poses_agree(seed):
    rot = Rotation.random(random_state=seed)
    from_quat = as_rotation(rot.as_quat())  # scipy's (x, y, z, w) order
    np.testing.assert_allclose(from_quat, rot.as_matrix(), atol=1e-12)
    np.testing.assert_allclose(as_rotation(rot.as_matrix()), rot.as_matrix(), atol=1e-12)


@pytest.mark.parametrize(
    "rotation, match",
    [
        (np.diag([1.0, 1.0, -1.0]), "not a rotation"),  # a reflection
        (np.eye(3) * 2, "not a rotation"),
        (np.ones((3, 3)), "not a rotation"),
        ((0, 0, 0, 0), "zero length"),
        ((0, 0, 1), "quaternion"),
        (np.full((3, 3), np.nan), "NaN"),
    ],
)
def test_a_pose_that_is_not_a_rotation_is_an_input_error(rotation, match):
    with pytest.raises(InputError, match=match) as e:
        box_obstacle((0.1, 0.1, 0.1), (0.5, 0, 0), rotation, name="wall")
    assert str(e.value).startswith("wall.rotation") and "\n" not in str(e.value)


def test_missing_mesh_and_a_file_that_is_not_a_mesh(tmp_path):
    with pytest.raises(UnknownNameError, match="does not exist"):
        mesh_obstacle(tmp_path / "nope.stl")
    bad = tmp_path / "bad.stl"
    bad.write_text("this is not a mesh\n")
    with pytest.raises(InputError, match="not a mesh file") as e:
        mesh_obstacle(bad)
    assert "\n" not in str(e.value)


def test_a_convex_mesh_file_loads_as_its_hull(tmp_path, caplog):
    v, faces = dented_cube(0.0)  # the fifth top vertex lies on the face: convex
    path = tmp_path / "cube.stl"
    write_stl(path, v, faces)
    with caplog.at_level(logging.INFO, logger="gdnplan.arm3d"):
        hull = load_mesh(path)
    assert not caplog.records and is_convex_mesh(v)
    d = coal_distance(hull, coal.Transform3s(), coal.Sphere(0.05), as_pose((0.4, 0, 0)))
    assert d == pytest.approx(0.4 - 0.1 - 0.05, abs=1e-6)


def test_a_non_convex_mesh_becomes_its_hull_with_a_logged_note(tmp_path, caplog):
    v, faces = dented_cube(0.15)
    path = tmp_path / "dented.stl"
    write_stl(path, v, faces)
    assert not is_convex_mesh(v)
    with caplog.at_level(logging.INFO, logger="gdnplan.arm3d"):
        obs = mesh_obstacle(path, name="dented")
    assert any("not convex" in r.getMessage() for r in caplog.records)
    # the hull is the full cube: a sphere above the dent is as far as from the cube's top
    d = coal_distance(obs.shape, obs.pose, coal.Sphere(0.05), as_pose((0, 0, 0.3)))
    assert d == pytest.approx(0.3 - 0.1 - 0.05, abs=1e-6)


@pytest.mark.parametrize("bad", ["nan 1 1", "1 inf 1", "1e9 1 1"])
def test_load_mesh_refuses_bad_vertices_before_computing_with_them(tmp_path, capfd, bad):
    """A NaN, infinite or far vertex: InputError naming the vertex or the distance, and no
    "eigen: too many iterations" lines on stderr (nothing computed with it first)."""
    corners = [f"{x} {y} {z}" for x in (0, 1) for y in (0, 1) for z in (0, 1)][:-1]
    faces = ["1 2 3", "2 3 4", "5 6 7", "6 7 8", "1 2 5", "2 5 6", "3 4 7", "4 7 8"]
    path = tmp_path / "cube.obj"
    path.write_text(
        "".join(f"v {c}\n" for c in [*corners, bad]) + "".join(f"f {f}\n" for f in faces)
    )
    with pytest.raises(InputError, match=r"NaN or infinite|beyond"):
        load_mesh(path, name="part")
    assert "eigen" not in capfd.readouterr().err


# points: every coordinate a real number; numpy's float conversion turned True into 1.0, "0.5"
# into 0.5 and 1 + 2j into 1.0 (with a ComplexWarning), so a convex or cloud obstacle of a
# problem file (or a .npy of another dtype) was built from numbers the user never wrote
NOT_REAL = st.one_of(
    st.booleans(),
    st.floats(-1.0, 1.0).map(str),
    st.complex_numbers(max_magnitude=1.0),
    st.none(),
    st.just([0.1]),
)


@given(
    points=st.lists(st.lists(st.floats(-1.0, 1.0), min_size=3, max_size=3), min_size=1),
    bad=NOT_REAL,
    where=st.tuples(st.integers(0, 10**6), st.integers(0, 2)),
)
@settings(max_examples=150, deadline=None)
def test_point_lists_with_a_non_real_coordinate_are_refused(points, bad, where):
    from gdnplan.arm3d.shapes import as_points

    assert np.array_equal(as_points(points, "p", min_points=1), np.asarray(points, float))
    row, column = where[0] % len(points), where[1]
    points[row][column] = bad
    with pytest.raises(InputError, match=r"^p: expected (real numbers|\(k, 3\))"):
        as_points(points, "p", min_points=1)


@pytest.mark.parametrize(
    "dtype, kind", [(bool, "booleans"), (complex, "complex numbers"), ("U3", "strings")]
)
def test_point_arrays_of_a_non_real_dtype_are_refused(dtype, kind):
    from gdnplan.arm3d.cloud3d import cloud_obstacle

    with pytest.raises(InputError, match=f"expected real numbers as coordinates, got {kind}"):
        cloud_obstacle(np.ones((5, 3)).astype(dtype), name="scan")
    assert cloud_obstacle(np.ones((5, 3), np.float16), name="scan").points.dtype == float


@pytest.mark.parametrize("scale", [[True, True, True], ["1", "1", "1"], [1, 1, 1 + 0j]])
def test_a_mesh_scale_of_non_numbers_is_refused(tmp_path, scale):
    path = tmp_path / "cube.stl"
    write_stl(path, CUBE, [(0, 1, 2), (4, 5, 6), (0, 4, 5), (1, 3, 7)])
    with pytest.raises(InputError, match=r"m\.scale: expected three positive numbers"):
        load_mesh(path, scale, name="m")


SIZES = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True, width=64),
    st.sampled_from([0.0, -0.5, 1e-7, 1e-6, 0.3, 1e3, 1e4]),
)
RAW_SHAPES = {
    "box": lambda s: coal.Box(s, 0.2, 0.2),
    "sphere": lambda s: coal.Sphere(s),
    "cylinder": lambda s: coal.Cylinder(0.1, s),
    "capsule": lambda s: coal.Capsule(s, 0.3),
}


@settings(max_examples=60, deadline=None)
@given(st.sampled_from(sorted(RAW_SHAPES)), SIZES, st.sampled_from(["obstacle", "held"]))
@example("box", float("nan"), "obstacle")  # the audit's cases: never hit by any distance
@example("sphere", -0.5, "held")
@example("box", 501.0, "obstacle")  # a 501 m side: within the builders' 1000 m
@example("box", 1001.0, "held")
def test_a_raw_coal_shape_is_checked_as_the_builders_check_it(kind, size, where):
    """obstacle(shape, …) and hold(robot, shape, …) take coal shapes: one out of the builders'
    ranges (NaN, negative, zero, beyond 1000 m) is an InputError, as box(), sphere(), …
    refuse it (a raw coal.Box(nan, …) in the scene was silently never hit)."""
    from gdnplan.arm3d import load_robot3d, obstacle
    from gdnplan.arm3d.held import hold

    sides = size  # coal.Box takes full sides; the sphere, capsule radius and cylinder length
    valid = bool(np.isfinite(sides)) and 1e-6 <= sides <= 1e3
    shape = RAW_SHAPES[kind](size)
    build = (
        (lambda: obstacle(shape, (0.5, 0.0, 0.3)))
        if where == "obstacle"
        else (lambda: hold(load_robot3d("ur5e"), shape))
    )
    if valid:
        build()
    else:
        with pytest.raises(InputError):
            build()


@settings(max_examples=40, deadline=None)
@given(
    st.lists(st.floats(-2.0, 2.0), min_size=3, max_size=3),
    st.floats(0.0, 3.0),
)
@example([50.0, 0.0, 0.0], 0.01)  # the audit's: a box hidden from the broad phase
def test_an_obstacle_sphere_must_enclose_its_shape(center, radius):
    """An Obstacle3D built by hand keeps its (center, radius) only when that sphere encloses
    the shape's: the broad phase skips pairs by it, and a wrong one hid the obstacle (a 0.6 m
    box through the arm read +0.0145 m instead of −0.119 m)."""
    from gdnplan.arm3d import Scene3D, load_robot3d, signed_distance3d
    from gdnplan.arm3d.scene3d import Obstacle3D

    good = box_obstacle((0.6, 0.6, 0.6), (0.4, 0.0, 0.3))
    center = np.asarray(center)
    encloses = np.linalg.norm(center - good.center) + good.radius <= radius
    if not encloses:
        with pytest.raises(InputError, match="do not enclose"):
            Obstacle3D("hand", good.shape, good.pose, center, radius)
        return
    robot = load_robot3d("ur5e")
    q = np.array([0.0, -1.2, 1.2, -1.5, -1.57, 0.0])
    hand = Obstacle3D("hand", good.shape, good.pose, center, radius)
    d = signed_distance3d(Scene3D(robot, [hand]), q)
    assert d == pytest.approx(signed_distance3d(Scene3D(robot, [good]), q), abs=1e-9)


def _fibonacci_sphere(n: int, radius: float = 0.1) -> np.ndarray:
    k = np.arange(n) + 0.5
    z = 1.0 - 2.0 * k / n
    phi = np.pi * (1.0 + 5.0**0.5) * k
    ring = np.sqrt(1.0 - z**2)
    return radius * np.stack([ring * np.cos(phi), ring * np.sin(phi), z], 1)


def test_a_dense_mesh_hull_is_checked_for_convexity_in_bounded_memory():
    """The convexity check measured every (facet, vertex) pair at once: 6 GB for a
    20 000-vertex sphere, a MemoryError (or the OOM killer) beyond; now blocks of
    DEPTH_BLOCK entries, and hull vertices (depth 0) are not measured."""
    import tracemalloc

    points = _fibonacci_sphere(5000)  # ~10 000 facets: the old check allocated 400 MB
    tracemalloc.start()
    try:
        is_convex = is_convex_mesh(points)
        mesh_hull(points, "dense")
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert is_convex and peak < 120e6


@settings(max_examples=30, deadline=None)
@given(
    st.integers(20, 300),
    st.floats(0.0, 0.09),
    st.integers(0, 40),
    st.integers(0, 2**16),
)
@example(200, 0.05, 40, 0)
def test_the_blocked_convexity_check_agrees_with_every_facet_and_vertex(n, depth, k, seed):
    """is_convex_mesh = no vertex deeper than CONVEX_TOLERANCE · diameter inside the hull,
    computed here on the full (facets, points) array."""
    from scipy.spatial import ConvexHull

    from gdnplan.arm3d import shapes

    rng = np.random.default_rng(seed)
    inner = rng.normal(size=(k, 3))
    inner *= (0.1 - depth) / np.maximum(np.linalg.norm(inner, axis=1), 1e-9)[:, None]
    points = np.concatenate([_fibonacci_sphere(n), inner])
    hull = ConvexHull(points)
    offsets = hull.equations[:, :3] @ points.T + hull.equations[:, 3:]
    deepest = float(np.max(-np.max(offsets, axis=0)))
    tol = shapes.CONVEX_TOLERANCE * float(np.linalg.norm(points.max(0) - points.min(0)))
    old_block = shapes.DEPTH_BLOCK
    try:
        shapes.DEPTH_BLOCK = 7 * len(hull.equations)  # several blocks of 7 points
        assert is_convex_mesh(points) == (deepest <= tol)
    finally:
        shapes.DEPTH_BLOCK = old_block


def test_a_mesh_of_too_many_vertices_names_the_fix():
    """ "expected (k, 3) points with 4 ≤ k ≤ 100000, got (3000000, 3)" named no fix."""
    from gdnplan.arm3d.shapes import MAX_HULL_POINTS

    points = _fibonacci_sphere(MAX_HULL_POINTS + 1)
    with pytest.raises(InputError, match=r"^dense: the mesh has 100001 vertices.*decimate"):
        mesh_hull(points, "dense")
