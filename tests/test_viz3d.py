"""The 3-D view: scene objects, the full robot's placements, the meshcat commands (headless)."""

import base64
import re
import sys

import numpy as np
import pinocchio as pin
import pytest
from shapely.geometry import Polygon
from shapely.ops import unary_union

from gdnplan.cli import run
from gdnplan.errors import GdnplanError, InputError
from gdnplan.robot import load_robot
from gdnplan.scene import Scene, make_scene
from gdnplan.ur5e import LOCKED, tcp_pose
from gdnplan.viz3d import (
    DEPTH,
    Prism,
    frame_poses,
    full_robot,
    held_stick,
    require_meshcat,
    scene_objects,
    send_plan,
    tool_offset,
)


@pytest.fixture(scope="module")
def fetch():
    return {g: make_scene("fetch", seed=0, gripper=g) for g in ("open", "holding")}


def test_scene_objects_extrude_the_convex_parts(fetch):
    scene = fetch["open"]
    objects = scene_objects(scene)
    assert len(objects) == len(scene.obstacle_parts)
    names = [o.name for o in objects]
    assert names[0] == "table" and names[-1] == "stick"
    assert sum(n.startswith("storage/") for n in names) == len(objects) - 2
    offset, plane = tool_offset(scene.robot), scene.robot.plane
    for obj, part in zip(objects, scene.obstacle_parts, strict=True):
        world = obj.world_vertices()
        m = len(part)
        for ring in (world[:m], world[m:]):
            np.testing.assert_allclose(plane.project(ring), part, atol=1e-12)
        out = (world - plane.origin) @ plane.normal
        np.testing.assert_allclose(out[:m], offset - obj.depth / 2, atol=1e-12)
        np.testing.assert_allclose(out[m:], offset + obj.depth / 2, atol=1e-12)
    assert objects[-1].depth == scene.info["stick_width"]
    assert objects[0].depth == DEPTH


def test_storage_box_matches_the_2d_polygon(fetch):
    scene = fetch["open"]
    plane = scene.robot.plane
    parts = [o for o in scene_objects(scene) if o.name.startswith("storage/")]
    footprint = unary_union(
        [Polygon(plane.project(p.world_vertices()[: len(p.polygon)])) for p in parts]
    )
    storage = Polygon(scene.info["storage"])
    assert footprint.symmetric_difference(storage).area < 1e-12
    assert footprint.area == pytest.approx(storage.area)


def test_prism_mesh_is_closed_and_faces_outward():
    polygon = np.array([[0.0, 0.0], [0.3, 0.0], [0.4, 0.2], [0.1, 0.3]])
    prism = Prism("p", polygon, 0.5, np.eye(4), 0)
    vertices, faces = prism.mesh()
    assert vertices.shape == (8, 3) and faces.shape == (12, 3)
    a, b, c = (vertices[faces[:, k]] for k in range(3))
    volume = np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6  # > 0 only for outward faces
    assert volume == pytest.approx(Polygon(polygon).area * 0.5)
    edges = np.sort(np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]]), 1)
    assert (np.unique(edges, axis=0, return_counts=True)[1] == 2).all()  # watertight


@pytest.mark.parametrize("gripper", ["open", "closed", "holding"])
def test_full_robot_reads_back_the_locked_joints(gripper):
    robot = load_robot("ur5e", gripper=gripper)
    full = full_robot(robot)
    values = dict(zip(list(full.model.names)[1:], full.q_locked, strict=True))
    for name, value in LOCKED.items():
        assert values[name] == pytest.approx(value, abs=1e-12)
    for side in ("left", "right"):
        assert values[f"{side}_finger_joint"] == pytest.approx(robot.info["opening"] / 2)
    assert full.model.nq == 8 and full.planning_index.tolist() == [1, 2, 3]


@pytest.mark.parametrize("name", ["ur5e", "ur5", "planar7"])
def test_full_robot_places_the_tool_where_the_planar_model_does(name, fetch):
    robot = fetch["open"].robot if name == "ur5e" else load_robot(name)
    full = full_robot(robot)
    reduced, rdata = robot.model, robot.model.createData()
    tool = robot.info.get("tcp_frame", reduced.frames[reduced.nframes - 1].name)
    qs = robot.sample(20, seed=3)
    if name == "ur5e":
        qs = np.vstack([qs, [fetch["open"].info[k] for k in ("q_home", "q_grasp", "q_out")]])
    for q in qs:
        data, _ = full.placements(q)
        pin.framesForwardKinematics(reduced, rdata, q)
        point = data.oMf[full.model.getFrameId(tool)].translation
        planar = tcp_pose(robot, q)[:2] if name == "ur5e" else robot.plane.project(point)
        np.testing.assert_allclose(robot.plane.project(point), planar, atol=1e-6)
        np.testing.assert_allclose(
            point, rdata.oMf[reduced.getFrameId(tool)].translation, atol=1e-6
        )
        out = robot.plane.normal @ (point - robot.plane.origin)
        assert out == pytest.approx(tool_offset(robot), abs=1e-9)


def test_held_stick_at_the_grasp_is_the_obstacle_stick(fetch):
    held = fetch["holding"]
    full = full_robot(held.robot)
    data, _ = full.placements(held.info["q_grasp"])
    stick = held_stick(held.robot, data, full)
    obstacle = next(o for o in scene_objects(fetch["open"]) if o.name == "stick")
    np.testing.assert_allclose(
        np.sort(stick.world_vertices(), 0), np.sort(obstacle.world_vertices(), 0), atol=1e-9
    )
    assert held_stick(fetch["open"].robot, data, full) is None


def test_frame_poses_follow_the_segments(fetch):
    open_, held = fetch["open"], fetch["holding"]
    reach = np.array([open_.info["q_pregrasp"], open_.info["q_grasp"]])
    out = np.array([held.info["q_lift"], held.info["q_out"]])
    frames = frame_poses([(open_, reach), (held, out)], per_segment=3)
    assert len(frames) == 2 * 4
    assert all("stick" in f.objects for f in frames)
    robot = frames[0].robot
    assert len(robot) == len(full_robot(open_.robot).geometry.geometryObjects)
    still, moved = frames[0].objects["stick"], frames[-1].objects["stick"]
    assert np.allclose(still.pose, frames[3].objects["stick"].pose)
    assert not np.allclose(still.pose, moved.pose)  # carried out of the box


def test_frame_poses_reject_mixed_robots(fetch):
    other = Scene(load_robot("planar2"), ())
    with pytest.raises(InputError, match="share one robot URDF"):
        frame_poses([(fetch["open"], np.zeros((2, 3))), (other, np.zeros((2, 2)))])
    with pytest.raises(InputError, match="no path"):
        frame_poses([])


def test_missing_meshcat_names_the_pip_command(monkeypatch):
    monkeypatch.setitem(sys.modules, "meshcat", None)  # import meshcat -> ImportError
    with pytest.raises(GdnplanError, match=r"pip install 'gdnplan\[viz3d\]'"):
        require_meshcat()


def test_cli_view3d_without_meshcat_fails_before_planning(monkeypatch, capsys):
    import gdnplan.trajopt

    monkeypatch.setitem(sys.modules, "meshcat", None)
    monkeypatch.setattr(gdnplan.trajopt, "plan", lambda *a, **k: pytest.fail("planned"))
    with pytest.raises(SystemExit) as exit_:
        run(["plan", "problems/planar2_square.toml", "--view3d"])
    assert exit_.value.code == 2
    assert "meshcat is not installed" in capsys.readouterr().err


def test_send_plan_loads_robot_objects_and_animation(fetch, meshcat_window):
    meshcat = pytest.importorskip("meshcat")
    open_ = fetch["open"]
    path = np.array([open_.info["q_pregrasp"], open_.info["q_grasp"]])
    n = send_plan(meshcat.Visualizer(window=meshcat_window), [(open_, path)], per_segment=2)
    assert n == 3
    objects = {c["path"] for c in meshcat_window.commands if c["type"] == "set_object"}
    geometry = full_robot(open_.robot).geometry.geometryObjects
    assert {f"/meshcat/ur5e/visuals/{g.name}" for g in geometry} <= objects
    assert {f"/meshcat/scene/{o.name}" for o in scene_objects(open_)} <= objects
    (animation,) = [c for c in meshcat_window.commands if c["type"] == "set_animation"]
    clips = {a["path"]: a["clip"] for a in animation["animations"]}
    assert len(clips) == len(geometry) + len(scene_objects(open_))
    keys = clips["/meshcat/scene/stick"]["tracks"][0]["keys"]
    assert [k["time"] for k in keys] == [0, 1, 2]
    (camera,) = [c for c in meshcat_window.commands if c["path"].endswith("rotated/<object>")]
    assert camera["path"] == "/Cameras/default/rotated/<object>"
    assert camera["value"][2] > 1.0  # y-up camera frame: in front of the x–z plane (world −y)


@pytest.mark.slow
def test_view_in_a_real_meshcat_server(fetch):
    meshcat = pytest.importorskip("meshcat")
    held = fetch["holding"]
    viewer = meshcat.Visualizer()  # starts a server subprocess
    try:
        send_plan(viewer, [(held, np.array([held.info["q_lift"], held.info["q_out"]]))])
        html = viewer.static_html()  # the server's scene tree, as the browser receives it
    finally:
        viewer.window.server_proc.kill()
        viewer.window.server_proc.wait()
    blobs = [base64.b64decode(b) for b in re.findall(r"base64,([A-Za-z0-9+/=]+)", html)]
    for needle in (b"/meshcat/scene/stick", b"/meshcat/ur5e/visuals/gripper_base_link_0"):
        assert any(b"set_object" in b and needle in b for b in blobs), needle
    assert any(b"set_animation" in b for b in blobs)
