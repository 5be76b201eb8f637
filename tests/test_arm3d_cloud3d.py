"""Point-cloud obstacles (gdnplan.arm3d.cloud3d): the octree is a superset of the points (its
distance is a lower bound within r√3 of the distance to the points), clouds coal would drop
points of are refused, problem files with ``type = "cloud"`` read, write back and fail in one
line, and a path certified against a cloud keeps its bound from the raw points."""

from __future__ import annotations

import json

import coal
import numpy as np
import pytest
import tomli_w
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

from gdnplan.arm3d import Scene3D, cloud_obstacle, load_robot3d, read_cloud
from gdnplan.arm3d.cloud3d import OCTREE_HALF_CELLS, octree
from gdnplan.arm3d.scene_file3d import scene3d_from_config
from gdnplan.arm3d.write_file3d import obstacle_table
from gdnplan.cli import run
from gdnplan.errors import GdnplanError, InputError, ProblemFileError
from gdnplan.exact import certify

REQUEST = coal.DistanceRequest()
REQUEST.enable_signed_distance = True


def _sphere_distance(shape, pose, center, radius) -> float:
    res = coal.DistanceResult()
    ball = coal.Transform3s(np.eye(3), np.asarray(center, float))
    return coal.distance(shape, pose, coal.Sphere(radius), ball, REQUEST, res)


@settings(max_examples=40, deadline=None)
@given(
    seed=st.integers(0, 10**6),
    k=st.integers(1, 60),
    r=st.sampled_from([0.005, 0.02, 0.05]),
)
def test_octree_distance_is_a_lower_bound_within_a_voxel_diagonal(seed, k, r):
    rng = np.random.default_rng(seed)
    pts = rng.uniform(-0.3, 0.3, (k, 3))
    tree = octree(pts, r)
    center = rng.uniform(-0.6, 0.6, 3)
    radius = 0.05
    exact = float(np.min(np.linalg.norm(pts - center, axis=1))) - radius
    d = _sphere_distance(tree, coal.Transform3s(), center, radius)
    if exact > 2 * r:  # apart: coal's octree distance is a lower bound within r√3 (+ rounding)
        assert exact - r * np.sqrt(3) - 1e-9 <= d <= exact + 1e-9
    elif exact < -1e-6:  # a point inside the ball: its voxel overlaps the ball
        assert d <= 0.0


def test_points_an_octree_would_drop_are_refused():
    far = np.array([[0.0, 0.0, 0.1], [40.0, 0.0, 0.0]])  # 40 m > 0.001 m · 2¹⁵ = 32.8 m
    with pytest.raises(InputError, match="beyond what an octree"):
        octree(far, 0.001)
    assert len(octree(far, 0.01).toBoxes()) == 2  # 40 m < 0.01 m · 2¹⁵: both points kept
    edge = 0.02 * OCTREE_HALF_CELLS
    with pytest.raises(InputError, match="beyond what an octree"):
        octree([[edge, 0.0, 0.0]], 0.02)


@pytest.mark.parametrize(
    "points, resolution, message",
    [
        (np.zeros((0, 3)), 0.02, "1 ≤ k"),
        (np.zeros((4, 2)), 0.02, r"\(k, 3\)"),
        ([[0.0, np.nan, 0.0]], 0.02, "NaN"),
        ([[0.0, 2e3, 0.0]], 0.02, "beyond 1000"),
        ("points", 0.02, "points"),
        ([[0.0, 0.0, 0.0]], 0.0, "voxel edge"),
        ([[0.0, 0.0, 0.0]], -0.1, "voxel edge"),
        ([[0.0, 0.0, 0.0]], True, "voxel edge"),
        ([[0.0, 0.0, 0.0]], "0.02", "voxel edge"),
        ([[0.0, 0.0, 0.0]], float("nan"), "voxel edge"),
        ([[0.0, 0.0, 0.0]], 5.0, "voxel edge"),
    ],
)
def test_bad_clouds_are_one_clear_error(points, resolution, message):
    with pytest.raises(InputError, match=message):
        cloud_obstacle(points, resolution)


def test_point_files_npy_and_text(tmp_path):
    pts = np.array([[0.5, 0.0, 0.2], [0.5, 0.1, 0.2], [0.51, -0.1, 0.35]])
    np.save(tmp_path / "c.npy", pts)
    (tmp_path / "c.xyz").write_text("# x y z\n0.5 0 0.2\n0.5, 0.1, 0.2\n0.51 -0.1 0.35 # last\n")
    assert np.array_equal(read_cloud(tmp_path / "c.npy"), pts)
    assert np.array_equal(read_cloud(tmp_path / "c.xyz"), pts)
    (tmp_path / "bom.xyz").write_text("\ufeff0.5 0 0.2\n0.5 0.1 0.2\n0.51 -0.1 0.35\n")
    assert np.array_equal(read_cloud(tmp_path / "bom.xyz"), pts)  # a UTF-8 byte-order mark
    (tmp_path / "bad.xyz").write_text("0.5 0 oops\n")
    (tmp_path / "two.xyz").write_text("0.5 0\n0.1 0.2\n")
    (tmp_path / "bin.npy").write_bytes(b"\x93NUMPY garbage")
    np.save(tmp_path / "obj.npy", np.array([{"a": 1}], dtype=object))
    for name in ("bad.xyz", "two.xyz", "bin.npy", "obj.npy"):
        with pytest.raises(InputError):
            read_cloud(tmp_path / name)
    with pytest.raises(GdnplanError, match="does not exist"):
        read_cloud(tmp_path / "missing.xyz")


def _npy_claiming(shape: tuple[int, ...], body: bytes = b"") -> bytes:
    """A version-1.0 .npy file whose header claims float64 ``shape``, followed by ``body``."""
    import io

    buf = io.BytesIO()
    header = {"descr": "<f8", "fortran_order": False, "shape": shape}
    np.lib.format.write_array_header_1_0(buf, header)
    return buf.getvalue() + body


@settings(
    max_examples=30, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(k=st.integers(1, 2**40), held=st.integers(0, 64))
@example(k=10**11, held=3)
def test_a_npy_header_claiming_more_than_its_file_is_refused_before_allocating(tmp_path, k, held):
    """np.load allocated the claimed size first: a 100-byte file claiming 10¹¹ points raised
    MemoryError (2.4 TB), or filled the memory; now an InputError naming the file."""
    if k * 3 * 8 <= held:
        return
    path = tmp_path / "claims.npy"
    path.write_bytes(_npy_claiming((k, 3), b"\0" * held))
    with pytest.raises(InputError, match=r"claims\.npy is not a point file \(its header claims"):
        read_cloud(path)


def test_a_truncated_npy_is_refused_and_a_whole_one_reads(tmp_path):
    pts = np.random.default_rng(0).uniform(0.3, 0.6, (1000, 3))
    np.save(tmp_path / "whole.npy", pts)
    data = (tmp_path / "whole.npy").read_bytes()
    (tmp_path / "cut.npy").write_bytes(data[:-8])
    assert np.array_equal(read_cloud(tmp_path / "whole.npy"), pts)
    with pytest.raises(InputError, match="truncated or damaged"):
        read_cloud(tmp_path / "cut.npy")


def _cfg(table: dict) -> dict:
    return {"robot": {"name": "ur5e"}, "scene3d": {"obstacles": [table]}}


def test_problem_file_cloud_reads_and_writes_back(tmp_path):
    pts = np.array([[0.45, -0.1, 0.3], [0.45, 0.1, 0.3], [0.46, 0.0, 0.5]])
    np.save(tmp_path / "scan.npy", pts)
    table = {"type": "cloud", "file": "scan.npy", "resolution": 0.03, "position": [0.0, 0.1, 0]}
    scene = scene3d_from_config(_cfg(table), tmp_path)
    (o,) = scene.obstacles
    assert isinstance(o.shape, coal.OcTree) and o.shape.getResolution() == 0.03
    assert np.array_equal(o.points, pts) and o.name == "cloud0"
    written = obstacle_table(o)
    assert written["type"] == "cloud" and written["resolution"] == 0.03
    again = scene3d_from_config(_cfg(written), tmp_path).obstacles[0]
    assert np.array_equal(again.points, pts)
    assert np.array_equal(np.asarray(again.pose.getTranslation()), [0.0, 0.1, 0.0])
    inline = scene3d_from_config(_cfg({"type": "cloud", "points": pts.tolist()}), tmp_path)
    assert inline.obstacles[0].shape.getResolution() == 0.02  # the default voxel edge


@pytest.mark.parametrize(
    "table, message",
    [
        ({"type": "cloud"}, "exactly one of points"),
        ({"type": "cloud", "points": [[0, 0, 0]], "file": "a.npy"}, "exactly one of points"),
        ({"type": "cloud", "file": "missing.npy"}, "does not exist"),
        ({"type": "cloud", "points": [[0, 0]]}, r"\(k, 3\)"),
        ({"type": "cloud", "points": [[0, 0, 0]], "resolution": 0}, "voxel edge"),
        ({"type": "cloud", "points": [[0, 0, 0]], "radius": 0.1}, "radius"),
    ],
)
def test_bad_cloud_tables_name_the_obstacle(tmp_path, table, message):
    with pytest.raises(ProblemFileError, match=message) as e:
        scene3d_from_config(_cfg(table), tmp_path)
    assert "[[scene3d.obstacles]] 0" in str(e.value) and "\n" not in str(e.value)


def test_a_held_object_cannot_be_a_cloud(tmp_path):
    cfg = {
        "robot": {"name": "ur5e", "held": {"type": "cloud", "points": [[0.0, 0.0, 0.1]]}},
        "scene3d": {},
    }
    with pytest.raises(ProblemFileError, match=r"\[robot.held\] type"):
        scene3d_from_config(cfg, tmp_path)


VALUES = st.one_of(
    st.none(),
    st.booleans(),
    st.integers(-(10**9), 10**9),
    st.floats(allow_nan=True, allow_infinity=True),
    st.text(max_size=8),
    st.lists(st.floats(allow_nan=True, allow_infinity=True), max_size=4),
    st.lists(st.lists(st.floats(-1e9, 1e9), min_size=0, max_size=4), max_size=5),
)


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    st.dictionaries(
        st.sampled_from(["points", "file", "resolution", "position", "rpy", "name"]), VALUES
    )
)
def test_any_cloud_table_either_reads_or_fails_in_one_line(tmp_path_factory, fields):
    table = {"type": "cloud", **fields}
    base = tmp_path_factory.mktemp("cloud")
    try:
        tomli_w.dumps(_cfg(table))
    except (TypeError, ValueError):
        return  # not a TOML document (None, NaN keys...): a file cannot hold it
    try:
        scene = scene3d_from_config(_cfg(table), base)
    except ProblemFileError as e:
        assert "\n" not in str(e) and str(e).startswith("[[scene3d.obstacles]] 0")
        return
    assert isinstance(scene.obstacles[0].shape, coal.OcTree)


def _raw_distance(scene: Scene3D, q: np.ndarray, points: np.ndarray) -> float:
    """Smallest distance (m) from the robot's link shapes to the raw points over q (T, dof)."""
    robot, best = scene.robot, np.inf
    for qt in q:
        for link, tf in zip(robot.shapes, robot.shape_placements(qt), strict=True):
            pose = coal.Transform3s(tf[:3, :3], tf[:3, 3])
            best = min(best, min(_sphere_distance(link.shape, pose, p, 1e-9) for p in points))
    return float(best)


def test_a_path_certified_against_a_cloud_keeps_its_bound_from_the_raw_points():
    rng = np.random.default_rng(4)
    n = 300
    pts = np.c_[np.full(n, 0.45), rng.uniform(-0.3, 0.3, n), rng.uniform(0.1, 0.7, n)]
    scene = Scene3D(load_robot3d("ur5e"), [cloud_obstacle(pts, 0.03, name="wall")])
    q0 = np.array([np.pi, -1.2, 1.0, -1.0, -1.57, 0.0])  # the arm turned away from the wall
    path = q0 + np.linspace(0.0, 1.0, 6)[:, None] * np.array([0.6, 0.3, -0.4, 0.2, 0.5, 0.1])
    cert = certify(scene, path, 0.0)
    assert cert.ok and cert.lower_bound > 0.0
    dense = path[0] + np.linspace(0.0, 1.0, 26)[:, None] * (path[-1] - path[0])
    assert _raw_distance(scene, dense, pts) >= cert.lower_bound - 1e-9


def test_gdnplan_plan_certifies_a_problem_file_with_a_scanned_cloud(tmp_path, capsys):
    rng = np.random.default_rng(5)
    n = 200
    pts = np.c_[np.full(n, 0.45), rng.uniform(-0.3, 0.3, n), rng.uniform(0.1, 0.7, n)]
    np.savetxt(tmp_path / "scan.xyz", pts, header="x y z")
    q0 = [np.pi, -1.2, 1.0, -1.0, -1.57, 0.0]
    q1 = [np.pi + 0.6, -0.9, 0.6, -0.8, -1.07, 0.1]
    cfg = {
        "robot": {"name": "ur5e"},
        "scene3d": {"obstacles": [{"type": "cloud", "file": "scan.xyz", "resolution": 0.03}]},
        "start": {"q": q0},
        "goal": {"q": q1},
        "options": {"waypoints": 8, "margin": 0.02},
    }
    (tmp_path / "cloud.toml").write_text(tomli_w.dumps(cfg))
    with pytest.raises(SystemExit) as e:
        run(["plan", str(tmp_path / "cloud.toml"), "--json", "-q"])
    assert e.value.code == 0
    result = json.loads(capsys.readouterr().out)
    assert result["success"] and result["min_distance"] > 0.02


@settings(max_examples=10, deadline=None)
@given(
    edge=st.sampled_from([0.001, 0.002, 0.005]),
    side=st.floats(0.3, 1.0),
    seed=st.integers(0, 2**16),
)
@example(edge=0.001, side=1.0, seed=0)  # 10⁶ voxels: 0.6 s per distance, plans for hours
def test_a_cloud_of_too_many_voxels_is_refused_with_a_resolution_that_fits(edge, side, seed):
    """A distance to an octree costs ~0.5 µs per occupied voxel: a dense scan at a fine
    resolution made every plan run for hours; it is refused, naming a resolution that the
    same points pass at."""
    from gdnplan.arm3d.cloud3d import MAX_VOXELS

    rng = np.random.default_rng(seed)
    pts = np.column_stack(
        [rng.uniform(0.5, 0.502, 300_000), rng.uniform(-side, side, (300_000, 2))]
    )
    voxels = len(np.unique(np.floor(pts / edge), axis=0))
    if voxels <= MAX_VOXELS:
        assert cloud_obstacle(pts, edge).points.shape == pts.shape
        return
    with pytest.raises(InputError, match=rf"occupy {voxels} voxels .*resolution = ") as e:
        cloud_obstacle(pts, edge, name="scan")
    suggested = float(str(e.value).split("resolution = ")[1].split(" m")[0])
    assert suggested > edge and len(np.unique(np.floor(pts / suggested), axis=0)) <= MAX_VOXELS
    cloud_obstacle(pts, suggested)
