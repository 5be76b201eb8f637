"""3-D plan views: meshes of the coal shapes, the GIF (frames, moving robot pixels), the meshcat
scene of a 3-D plan (headless) and the CLI's --animate / --view3d for 3-D problems."""

import itertools
import sys

import coal
import numpy as np
import pinocchio as pin
import pytest
from PIL import Image
from scipy.spatial import ConvexHull

from gdnplan.arm3d import Scene3D, box_obstacle, load_robot3d, sphere_obstacle
from gdnplan.arm3d.held import hold, stick
from gdnplan.arm3d.ik3d import tool_frame
from gdnplan.arm3d.shapes import capsule, convex, cylinder
from gdnplan.cli import run
from gdnplan.errors import InputError
from gdnplan.timing import time_path
from gdnplan.viz3d import (
    animate_paths3d,
    frames3d,
    obstacle_triangles,
    robot_triangles,
    scene3d_meshes,
    send_plan3d,
    shape_mesh,
    tool_positions,
)
from gdnplan.viz3d.animate import ROBOT_RGB

START = [-0.6, -1.2, 1.2, -1.5, -1.57, 0.0]
UP = [0.0, -1.57, 0.0, -1.57, -1.57, 0.0]
GOAL = [0.6, -1.2, 1.2, -1.5, -1.57, 0.0]


@pytest.fixture(scope="module")
def post():
    return Scene3D(
        load_robot3d("ur5e"),
        [box_obstacle((0.1, 0.1, 0.6), (0.45, 0.0, 0.3)), sphere_obstacle(0.08, (0, 0.5, 0.6))],
    )


def closed(faces: np.ndarray) -> bool:
    """Every edge of the triangle mesh is shared by exactly two triangles."""
    edges = np.sort(np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]]), 1)
    return set(np.unique(edges, axis=0, return_counts=True)[1].tolist()) == {2}


def on_surface(shape, v: np.ndarray) -> np.ndarray:
    """(k,) distance of points v (k, 3) from the primitive's surface (analytic, m)."""
    rho, z = np.linalg.norm(v[:, :2], axis=1), v[:, 2]
    if isinstance(shape, coal.Box):
        return np.max(np.abs(np.abs(v) - np.asarray(shape.halfSide)), axis=1)
    if isinstance(shape, coal.Sphere):
        return np.abs(np.linalg.norm(v, axis=1) - shape.radius)
    h, r = shape.halfLength, shape.radius
    if isinstance(shape, coal.Cylinder):  # the side (ρ = r, |z| ≤ h) or a cap (|z| = h, ρ ≤ r)
        side = np.abs(rho - r) + np.maximum(np.abs(z) - h, 0)
        cap = np.abs(np.abs(z) - h) + np.maximum(rho - r, 0)
        return np.minimum(side, cap)
    axis = np.column_stack([np.zeros((len(v), 2)), np.clip(z, -h, h)])  # capsule: segment + r
    return np.abs(np.linalg.norm(v - axis, axis=1) - r)


@pytest.mark.parametrize(
    "shape, volume",
    [
        (coal.Box(0.1, 0.2, 0.3), 0.006),
        (coal.Sphere(0.1), 4 / 3 * np.pi * 0.1**3),
        (cylinder(0.1, 0.4), np.pi * 0.1**2 * 0.4),
        (capsule(0.1, 0.4), np.pi * 0.1**2 * 0.4 + 4 / 3 * np.pi * 0.1**3),
    ],
)
def test_primitive_meshes_are_closed_inscribed_and_fill_the_shape(shape, volume):
    vertices, faces = shape_mesh(shape)
    assert closed(faces)
    assert np.max(on_surface(shape, vertices)) < 1e-12  # every vertex on the surface
    ratio = ConvexHull(vertices).volume / volume
    assert 0.9 < ratio <= 1 + 1e-9  # inscribed: never larger than the shape


def test_convex_mesh_is_the_hull_of_its_points():
    rng = np.random.default_rng(0)
    points = rng.normal(size=(40, 3))
    vertices, faces = shape_mesh(convex(points))
    assert closed(faces)
    hull = ConvexHull(points)
    assert ConvexHull(vertices).volume == pytest.approx(hull.volume, rel=1e-9)


def test_robot_triangles_follow_pinocchio_placements():
    robot = load_robot3d("ur5e")
    shape, placement = stick(0.3, 0.03)
    held = hold(robot, shape, placement)
    q = held.random_configurations(3, np.random.default_rng(1))
    tris, owner = robot_triangles(held, q)
    assert tris.shape[1:] == (len(owner), 3, 3) and set(owner) == set(range(len(held.shapes)))
    for b in range(len(q)):
        poses = held.shape_placements(q[b])  # Pinocchio, one configuration
        for k, s in enumerate(held.shapes):
            v, f = shape_mesh(s.shape)
            expect = (v @ poses[k][:3, :3].T + poses[k][:3, 3])[f]
            np.testing.assert_allclose(tris[b, owner == k], expect, atol=1e-9)
    data = held.model.createData()
    pin.framesForwardKinematics(held.model, data, q[0])
    frame = held.model.getFrameId(tool_frame(held))
    np.testing.assert_allclose(tool_positions(held, q[:1])[0], data.oMf[frame].translation)


def test_obstacle_triangles_sit_at_the_obstacle_poses(post):
    tris, owner = obstacle_triangles(post)
    box = tris[owner == 0].reshape(-1, 3)
    np.testing.assert_allclose(box.min(0), [0.4, -0.05, 0.0], atol=1e-12)
    np.testing.assert_allclose(box.max(0), [0.5, 0.05, 0.6], atol=1e-12)
    ball = tris[owner == 1].reshape(-1, 3)
    np.testing.assert_allclose(np.linalg.norm(ball - [0, 0.5, 0.6], axis=1), 0.08, atol=1e-12)


def robot_pixels(frame: Image.Image) -> np.ndarray:
    """(k, 2) pixel coordinates whose colour is a shade of the robot's orange."""
    rgb = np.asarray(frame.convert("RGB"), float) / 255
    hue = rgb / np.maximum(rgb.max(2, keepdims=True), 1e-9)
    target = ROBOT_RGB / ROBOT_RGB.max()
    close = np.linalg.norm(hue - target, axis=2) < 0.15
    return np.argwhere(close & (rgb.max(2) > 0.3))


def test_gif_has_the_frames_and_the_robot_moves(post, tmp_path):
    out = tmp_path / "plan.gif"
    path = np.array([START, UP, GOAL])
    n = animate_paths3d([(post, path)], out, frames=8, title="post", margin=0.02, dpi=50)
    assert n == 8
    gif = Image.open(out)
    assert gif.n_frames == 8 and gif.size == (500, 250)
    frames = []
    for k in range(8):
        gif.seek(k)
        frames.append(gif.convert("RGB"))
    first, last = robot_pixels(frames[0]), robot_pixels(frames[-1])
    assert len(first) > 100 and len(last) > 100  # the arm is drawn
    assert np.linalg.norm(first.mean(0) - last.mean(0)) > 10  # ... and it has moved (pixels)
    assert all(np.any(np.asarray(a) != np.asarray(b)) for a, b in itertools.pairwise(frames))


def test_gif_of_a_timed_trajectory_and_a_held_object(post, tmp_path):
    robot = hold(post.robot, *stick(0.3, 0.03))
    scene = Scene3D(robot, post.obstacles[1:])
    traj = time_path(np.array([UP, GOAL]), 2.0)
    out = tmp_path / "timed.gif"
    assert animate_paths3d([(scene, traj)], out, frames=4, dpi=40) == 4
    assert Image.open(out).n_frames == 4


def test_gif_refuses_bad_stages(post, tmp_path):
    path = np.array([START, GOAL])
    traj = time_path(path, 1.0)
    with pytest.raises(InputError, match="TimedTrajectory"):
        animate_paths3d([(post, path), (post, traj)], tmp_path / "x.gif")
    with pytest.raises(InputError, match="frames"):
        animate_paths3d([(post, path)], tmp_path / "x.gif", frames=1)
    with pytest.raises(InputError, match="fps"):
        animate_paths3d([(post, path)], tmp_path / "x.gif", fps=0)
    with pytest.raises(InputError, match="no path"):
        animate_paths3d([], tmp_path / "x.gif")
    assert not (tmp_path / "x.gif").exists()


def test_meshcat_scene_of_a_3d_plan(post, meshcat_window):
    meshcat = pytest.importorskip("meshcat")
    path = np.array([START, UP, GOAL])
    names, poses = frames3d([(post, path)], per_segment=3)
    assert poses.shape == (7, len(post.robot.shapes), 4, 4)
    np.testing.assert_allclose(poses[-1], post.robot.shape_placements(np.array(GOAL)), atol=1e-9)
    meshes = scene3d_meshes(post, np.array(START))
    assert [m.name for m in meshes[: len(names)]] == names
    assert len(meshes) == len(names) + len(post.obstacles)
    viewer = meshcat.Visualizer(window=meshcat_window)
    assert send_plan3d(viewer, [(post, path)], per_segment=3) == 7
    objects = {c["path"] for c in meshcat_window.commands if c["type"] == "set_object"}
    assert {f"/meshcat/{m.name}" for m in meshes} == objects
    (animation,) = [c for c in meshcat_window.commands if c["type"] == "set_animation"]
    assert {a["path"] for a in animation["animations"]} == {f"/meshcat/{n}" for n in names}


def test_cli_animate_3d_bad_path_fails_before_planning(monkeypatch, capsys, tmp_path):
    import gdnplan.trajopt

    monkeypatch.setattr(gdnplan.trajopt, "plan", lambda *a, **k: pytest.fail("planned"))
    for bad in (tmp_path / "x.png", tmp_path / "no_dir_file" / "x.gif"):
        (tmp_path / "no_dir_file").write_text("")
        with pytest.raises(SystemExit) as exit_:
            run(["plan", "ur5e_boxes3d", "--animate", str(bad)])
        assert exit_.value.code == 2
        err = capsys.readouterr().err.strip()
        assert err.count("\n") == 0 and "--animate" in err


def test_cli_view3d_3d_without_meshcat_fails_before_planning(monkeypatch, capsys):
    import gdnplan.trajopt

    monkeypatch.setitem(sys.modules, "meshcat", None)
    monkeypatch.setattr(gdnplan.trajopt, "plan", lambda *a, **k: pytest.fail("planned"))
    with pytest.raises(SystemExit) as exit_:
        run(["plan", "panda_shelf3d", "--view3d"])
    assert exit_.value.code == 2
    assert "meshcat is not installed" in capsys.readouterr().err


@pytest.mark.slow
def test_cli_plans_and_animates_a_3d_problem(tmp_path, capsys):
    out = tmp_path / "u.gif"
    with pytest.raises(SystemExit) as exit_:
        run(["plan", "ur5e_boxes3d", "--animate", str(out), "--max-acceleration", "5", "-q"])
    assert exit_.value.code == 0
    text = capsys.readouterr().out
    assert "certified collision-free" in text and "smooth curve, certified clearance" in text
    gif = Image.open(out)
    assert gif.n_frames == 60 and len(robot_pixels(gif.convert("RGB"))) > 100
