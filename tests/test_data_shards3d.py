"""3-D shards: labels equal an independent coal evaluation, shards are pure functions of their
settings, resuming keeps finished shards, other settings are refused, Ray writes the same bytes."""

from __future__ import annotations

import json
import os
import signal

import numpy as np
import pytest

from gdnplan.arm3d import Checker3D, random_boxes
from gdnplan.cli import run
from gdnplan.data.samples3d import (
    BOUNDARY_BAND,
    SCENE_SAMPLES,
    boxes_scene,
    env_robot3d,
    make_shard3d,
    obstacle_robot,
    scene_boxes,
)
from gdnplan.data.shards3d import generate3d
from gdnplan.errors import InputError


def test_shard_is_a_pure_function_with_coal_labels():
    a = make_shard3d("ur5e_boxes", 3, SCENE_SAMPLES, 2 * SCENE_SAMPLES, near=0.5)
    b = make_shard3d("ur5e_boxes", 3, SCENE_SAMPLES, 2 * SCENE_SAMPLES, near=0.5)
    assert all(np.array_equal(a[k], b[k]) for k in a)
    assert list(a["scene_seed"]) == [3 * 10**8 + 1, 3 * 10**8 + 2]
    robot = env_robot3d("ur5e_boxes")
    assert np.all(robot.within_limits(a["q"]))
    # the labels again, from the scene rebuilt by random_boxes and a brute-force checker
    for s in range(2):
        scene = random_boxes(obstacle_robot("ur5e"), 20, seed=int(a["scene_seed"][s]))
        rows = np.flatnonzero(a["scene"] == s)
        res = Checker3D(scene).evaluate(a["q"][rows], broad_phase=False, gradient=True)
        np.testing.assert_allclose(a["d"][rows], res.distance, atol=1e-9)
        np.testing.assert_allclose(a["grad"][rows], res.gradient, atol=1e-9)
    assert np.mean(np.abs(a["d"]) < BOUNDARY_BAND) >= 0.4  # near = 0.5 (plus uniform ones)


def test_labels_leave_self_collision_out():
    robot = env_robot3d("ur5e_boxes")
    assert len(robot.self_pairs) > 0 and len(obstacle_robot("ur5e").self_pairs) == 0
    centers, sizes = scene_boxes("ur5e_boxes", 5)
    scene = boxes_scene(obstacle_robot("ur5e"), centers, sizes)
    assert Checker3D(scene).n_pairs == len(robot.shapes) * 20


def test_start_must_align_with_scenes():
    with pytest.raises(InputError, match="multiple"):
        make_shard3d("ur5e_boxes", 0, 7, 10)


def test_resume_keeps_shards_and_matches_a_one_shot_run(tmp_path):
    one = generate3d("ur5e_boxes", 150, 2, tmp_path / "one", workers=1, shard_size=50)
    part = tmp_path / "part"
    generate3d("ur5e_boxes", 100, 2, part, workers=1, shard_size=50)
    first = (part / "shard_0000.npz").stat().st_mtime_ns
    generate3d("ur5e_boxes", 150, 2, part, workers=2, shard_size=50)
    assert (part / "shard_0000.npz").stat().st_mtime_ns == first
    for k in range(3):
        name = f"shard_{k:04d}.npz"
        assert (one / name).read_bytes() == (part / name).read_bytes()
    assert json.loads((part / "manifest.json").read_text())["shard_size"] == 50


@pytest.mark.parametrize(
    "change, message",
    [({"seed": 3}, "--seed"), ({"near": 0.5}, "--near"), ({"shard_size": 100}, "--shard-size")],
)
def test_other_settings_are_refused(tmp_path, change, message):
    args = {"seed": 2, "near": 0.0, "shard_size": 50}
    generate3d("ur5e_boxes", 50, out_dir=tmp_path, workers=1, **args)
    with pytest.raises(InputError, match=message):
        generate3d("ur5e_boxes", 50, out_dir=tmp_path, workers=1, **(args | change))
    with pytest.raises(InputError, match="already holds 50 samples"):
        generate3d("ur5e_boxes", 10, out_dir=tmp_path, workers=1, **args)


@pytest.mark.parametrize(
    "kwargs, message",
    [
        ({"env": "ur5e"}, "env"),
        ({"n": 0}, "n:"),
        ({"near": 2.0}, "near"),
        ({"shard_size": 30}, "shard_size"),
    ],
)
def test_bad_arguments(tmp_path, kwargs, message):
    args = {"env": "ur5e_boxes", "n": 50, "seed": 0, "out_dir": tmp_path} | kwargs
    with pytest.raises(InputError, match=message):
        generate3d(**args)


def test_cli_generates_3d_shards(tmp_path, capsys):
    with pytest.raises(SystemExit) as e:
        run(
            [
                "generate",
                "--env",
                "ur5e_boxes",
                "--n",
                "50",
                "--workers",
                "1",
                "--data",
                str(tmp_path),
            ]
        )
    assert e.value.code == 0
    assert (tmp_path / "ur5e_boxes" / "train" / "shard_0000.npz").exists()
    with pytest.raises(SystemExit) as e:
        run(["generate", "--env", "a", "--ray"])
    assert e.value.code == 2 and "--ray: only for the 3-D" in capsys.readouterr().err


def test_ray_writes_the_same_shards_as_the_local_pool(tmp_path):
    """A local Ray instance (≈ 5 s to start) writes byte-identical shards; CI must run it."""
    if os.environ.get("CI") != "true":
        pytest.importorskip("ray")
    local = generate3d("ur5e_boxes", 150, 4, tmp_path / "local", workers=2, near=0.2, shard_size=50)
    before = signal.getsignal(signal.SIGTERM)
    ray = generate3d("ur5e_boxes", 150, 4, tmp_path / "ray", near=0.2, shard_size=50, ray="local")
    names = sorted(p.name for p in local.glob("shard_*.npz"))
    assert names == sorted(p.name for p in ray.glob("shard_*.npz")) and len(names) == 3
    assert signal.getsignal(signal.SIGTERM) is before  # Ray's handler does not outlive it
    for name in names:
        assert (local / name).read_bytes() == (ray / name).read_bytes()


def test_cloud_shard_labels_are_the_distance_to_the_balls_around_the_points():
    from gdnplan.data.samples3d import POINT_RADIUS, cloud_scene

    a = make_shard3d("ur5e_cloud", 2, 0, SCENE_SAMPLES)
    pts = a["points"][0]
    assert pts.shape == (400, 3) and np.all(pts[:, 2] > -0.05)
    robot = obstacle_robot("ur5e")
    rows = np.arange(5)
    res = Checker3D(cloud_scene(robot, pts)).evaluate(a["q"][rows], broad_phase=False)
    np.testing.assert_allclose(a["d"][rows], res.distance, atol=1e-9)
    # independent: distance of every link shape to every point minus the radius, by coal
    import coal

    tf = robot.shape_placements(a["q"][0])
    best = np.inf
    for s, t in zip(robot.shapes, tf, strict=True):
        for p in pts:
            r = coal.DistanceResult()
            d = coal.distance(
                s.shape,
                coal.Transform3s(t[:3, :3], t[:3, 3]),
                coal.Sphere(1e-9),
                coal.Transform3s(np.eye(3), p),
                coal.DistanceRequest(),
                r,
            )
            best = min(best, d - POINT_RADIUS)
    if best > 0:
        np.testing.assert_allclose(a["d"][0], best, atol=1e-6)
