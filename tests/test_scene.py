import numpy as np
import pytest
from shapely.geometry import Point, Polygon

import gdnplan as gp
import gdnplan.scene as scene_mod
from gdnplan import geometry
from gdnplan.scene import scene_from_config

PAPER_ENVS = ["a", "b", "c", "d", "e"]


@pytest.mark.parametrize("env", PAPER_ENVS)
def test_environments_match_the_paper(env):
    scene = gp.make_scene(env, seed=4)
    expected = {"a": (2, 1), "b": (2, 1), "c": (7, 20), "d": (7, 20), "e": (7, 5)}[env]
    assert (scene.robot.dof, len(scene.obstacles)) == expected
    base = Point(0, 0)
    for poly in scene.obstacles:
        assert Polygon(poly).distance(base) > scene.robot.base_radius
        if env in "abcd":
            side = 0.3 if env in "ab" else 0.2
            assert Polygon(poly).area == pytest.approx(side**2)
        else:
            assert len(poly) <= 15


@pytest.mark.parametrize("env", PAPER_ENVS)
def test_generators_are_seeded(env):
    a, b = gp.make_scene(env, seed=7), gp.make_scene(env, seed=7)
    for p, r in zip(a.obstacles, b.obstacles, strict=True):
        np.testing.assert_array_equal(p, r)


def test_random_environments_change_with_seed_fixed_ones_do_not():
    for env, fixed in [("a", True), ("b", False), ("c", True), ("d", False), ("e", False)]:
        same = np.array_equal(
            gp.make_scene(env, seed=1).obstacles[0], gp.make_scene(env, seed=2).obstacles[0]
        )
        assert same == fixed, env


def test_collision_fraction_per_environment(record_property):
    """Benchmarks stay honest: random configurations collide often enough to matter."""
    fractions = {}
    for env in PAPER_ENVS:
        per_seed = []
        for seed in range(6):
            scene = gp.make_scene(env, seed=seed)
            q = scene.robot.sample(500, seed=seed)
            per_seed.append(np.mean(gp.signed_distance(scene, q) <= 0))
        fractions[env] = float(np.mean(per_seed))
        record_property(f"collision_fraction_{env}", fractions[env])
    assert fractions["d"] >= 0.25
    assert all(0.05 < f < 0.6 for f in fractions.values()), fractions


def test_scene_from_config_combines_generator_and_polygons():
    cfg = {
        "robot": {"name": "planar7"},
        "scene": {"generator": "d", "seed": 12},
        "obstacles": [{"polygon": [[1.0, 0.2], [1.3, 0.2], [1.3, 0.5], [1.0, 0.5]]}],
    }
    scene = scene_from_config(cfg)
    assert len(scene.obstacles) == 21
    assert scene.name == "d"


@pytest.mark.parametrize(
    ("cfg", "error", "field"),
    [
        ({"robot": {"name": "planar9"}}, gp.UnknownNameError, "robot"),
        ({"robot": {"name": "planar2"}, "scene": {"generator": "z"}}, gp.UnknownNameError, "scene"),
        ({"scene": {}}, gp.ProblemFileError, "robot"),
        (
            {"robot": {"name": "planar2"}, "obstacles": [{"poly": []}]},
            gp.ProblemFileError,
            "polygon",
        ),
        (
            {"robot": {"name": "planar2"}, "obstacles": [{"polygon": [[0, 0], [1, 0]]}]},
            gp.ProblemFileError,
            "obstacles",
        ),
        (
            {"robot": {"name": "planar2"}, "scene": {"generator": "d", "seed": "x"}},
            gp.ProblemFileError,
            "seed",
        ),
    ],
)
def test_bad_scene_config_names_the_field(cfg, error, field):
    with pytest.raises(error, match=field):
        scene_from_config(cfg)


def test_scene_rejects_obstacles_far_beyond_the_reach():
    robot = gp.make_scene("a").robot
    bound = scene_mod.coordinate_bound(robot)
    far = geometry.square((bound + 1.0, 0.0), 0.3)
    with pytest.raises(gp.InputError, match=r"obstacles\[1\].*limit"):
        scene_mod.Scene(robot, (geometry.square((0.6, 0.45), 0.3), far))
    scene_mod.Scene(robot, (geometry.square((bound - 1.0, 0.0), 0.3),))


def test_scene_rejects_a_thin_sliver_before_coal_sees_it():
    robot = gp.make_scene("a").robot
    sliver = np.array([[0.5, 0.5], [1.5, 0.5], [1.0, 0.5 + 1e-8]])
    with pytest.raises(gp.InputError, match=r"obstacles\[0\].*thick"):
        scene_mod.Scene(robot, (sliver,))


@pytest.mark.parametrize(
    ("cfg", "field"),
    [
        ({"robot": {"name": "planar2"}, "scene": {"generator": "a", "seed": -1}}, "seed"),
        ({"robot": {"name": "planar2"}, "scene": {"generator": "a", "seed": True}}, "seed"),
        ({"robot": {"name": "planar2"}, "scene": {"generator": "a", "bogus": 1}}, r"\[scene\]"),
        ({"robot": {"name": "ur5e", "bogus": 1}}, r"\[robot\]"),
        ({"robot": {"name": 3}}, "name"),
        (
            {
                "robot": {"name": "planar2"},
                "obstacles": [{"polygon": [[1, 0], [2, 0], [2, 1]], "x": 1}],
            },
            "unknown",
        ),
    ],
)
def test_scene_config_errors_are_problem_file_errors(cfg, field):
    with pytest.raises(gp.ProblemFileError, match=field):
        scene_mod.scene_from_config(cfg)


@pytest.mark.parametrize(
    ("build", "message"),
    [
        (lambda: gp.make_scene("d", n=5), r"^scene 'd': unknown option\(s\) \['n'\]; it takes no"),
        (
            lambda: gp.make_scene("fetch", griper="open"),
            r"^scene 'fetch': unknown option\(s\) \['griper'\] \(did you mean 'gripper'\?\)",
        ),
        (
            lambda: gp.load_robot("ur5e", stick_lenght=0.3),
            r"^robot 'ur5e': unknown option\(s\) \['stick_lenght'\] \(did you mean 'stick_length",
        ),
        (lambda: gp.load_robot(["planar2"]), r"^robot: expected a name, got list"),
        (lambda: gp.make_scene({"a": 1}), r"^scene: expected a name, got dict"),
    ],
    ids=["no options", "scene typo", "robot typo", "robot list", "scene dict"],
)
def test_unknown_factory_options_and_unhashable_names_are_gdnplan_errors(build, message):
    """Python raised TypeError ("unexpected keyword argument", "unhashable type: 'list'")."""
    with pytest.raises(gp.GdnplanError, match=message):
        build()
