"""Scenes: a robot among obstacle polygons, and the generators of the paper's environments.

Environments (paper §V-A, Fig. 4):

====  =========  ==================================================================
name  robot      obstacles
====  =========  ==================================================================
a     planar2    one fixed 0.3 m square
b     planar2    one 0.3 m square at a random pose within reach
c     planar7    20 squares of 0.2 m at a fixed layout (layout of ``d`` with seed 2022)
d     planar7    20 squares of 0.2 m, random centres in [-2, 2]², random rotations
e     planar7    5 random α-shapes: 20 uniform points in a unit square, α = 0.6
                 (circumradius bound), largest piece, at most 15 vertices, scaled to 0.7 m
====  =========  ==================================================================

No obstacle comes within ``robot.base_radius`` of the first joint (the random polygons:
:mod:`gdnplan.obstacle_draws`).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field, replace
from functools import cached_property
from pathlib import Path

import numpy as np

from .errors import InputError, ProblemFileError
from .geometry import as_polygon, convex_decomposition, square
from .limits import check_int, read_only
from .obstacle_draws import clear_of_base as clear_of_base
from .obstacle_draws import place_clear, random_squares
from .obstacle_draws import random_alpha_shape as random_alpha_shape
from .registry import SCENES
from .robot import Robot, factory_options, load_robot, robot_names, robot_options
from .scene_checks import (
    MAX_OBSTACLES,
    MAX_PARTS,
    call_reporting,
    check_obstacles,
    check_robot,
    coordinate_bound,
    describe,
    no_unknown_keys,
)

# problem-file keys (docs/problem_file.md documents each; tests/test_problem_file_docs.py checks)
ROBOT_KEYS = frozenset({"name"})  # [robot]; plus the options of the named robot (robot_options)
SCENE_KEYS = frozenset({"generator", "seed"})  # [scene]; plus the generator's (scene_options)
OBSTACLE_KEYS = frozenset({"polygon"})  # each [[obstacles]] table


@dataclass(frozen=True, eq=False)
class Scene:
    """A robot and the obstacles around it (world plane coordinates, metres).

    Attributes:
        robot: the robot (with its current gripper state, where it has one).
        obstacles: simple CCW polygons (m, 2); non-convex ones are split for coal. Checked:
            at most ``MAX_OBSTACLES`` polygons of ``geometry.MAX_VERTICES`` vertices,
            finite, within :func:`coordinate_bound` of joint 1, no repeated vertices, every
            convex part at least ``geometry.MIN_THICKNESS`` thick (:func:`check_part`).
        name: generator name or ``"custom"``.
        seed: generator seed, when generated.
        info: generator metadata (e.g. the fetch scene's storage and stick).
    """

    robot: Robot
    obstacles: tuple[np.ndarray, ...]
    name: str = "custom"
    seed: int | None = None
    info: dict = field(default_factory=dict)

    def __post_init__(self) -> None:
        check_robot(self.robot)
        obstacles = check_obstacles(self.obstacles, self.robot)
        # read-only copies: the coal checker and the parts are built from them once, so an
        # in-place change (obstacle += offset) must raise, not leave them as they were
        object.__setattr__(self, "obstacles", tuple(read_only(o) for o in obstacles))

    @cached_property
    def obstacle_parts(self) -> tuple[np.ndarray, ...]:
        """Convex CCW parts of all obstacles (what coal sees)."""
        return tuple(
            read_only(part) for poly in self.obstacles for part in convex_decomposition(poly)
        )

    @cached_property
    def part_owner(self) -> np.ndarray:
        """(P,) index of the obstacle each convex part comes from."""
        sizes = [len(convex_decomposition(p)) for p in self.obstacles]
        return np.repeat(np.arange(len(self.obstacles)), sizes)

    def with_robot(self, robot: Robot) -> Scene:
        """The same obstacles with another robot (e.g. the gripper holding a stick)."""
        return replace(self, robot=robot)

    def with_obstacles(self, obstacles) -> Scene:
        """The same robot with other obstacles."""
        return replace(self, obstacles=tuple(obstacles))


KINDS = {"planar": "a planar Scene", "3d": "a Scene3D", "any": "a planar Scene or a Scene3D"}


def check_scene(scene, kind: str = "planar", use: str = "", name: str = "scene") -> None:
    """The one type check of every public function taking a scene: InputError naming ``name``
    unless ``scene`` is a planar :class:`Scene` (``kind="planar"``), a
    :class:`~gdnplan.arm3d.Scene3D` (``"3d"``) or either (``"any"``). ``use`` names the function
    for the other kind (``"gdnplan.arm3d.signed_distance3d"``), which the message points to."""
    if isinstance(scene, Scene) and kind != "3d":
        return
    from .arm3d.scene3d import Scene3D  # on demand: arm3d imports this module

    if isinstance(scene, Scene3D) and kind != "planar":
        return
    if isinstance(scene, (Scene, Scene3D)):
        other = "a 3-D scene (Scene3D)" if isinstance(scene, Scene3D) else "a planar scene (Scene)"
        raise InputError(f"{name}: {other}: use {use}" if use else f"{name}: {other}")
    hint = ""
    if isinstance(scene, str) and kind != "3d" and scene in SCENES:
        hint = f"; build it first: gdnplan.make_scene({scene!r})"
    raise InputError(f"{name}: expected {KINDS[kind]}, got {describe(scene)}{hint}")


# -------------------------------------------------------------------- generators
def register_scene(name: str) -> Callable:
    """Decorator registering ``factory(seed, **options) -> Scene`` for :func:`make_scene`."""
    return SCENES.register(name)


def scene_names() -> list[str]:
    return SCENES.names()


def scene_options(name: str) -> set[str]:
    """The options :func:`make_scene` takes for the generator ``name`` besides ``seed`` (e.g.
    ``gripper`` for fetch): the ``[scene]`` keys beyond ``generator`` and ``seed``."""
    return factory_options(SCENES.get(name)) - {"seed"}


def make_scene(name: str, seed: int = 0, **options) -> Scene:
    """Build the scene ``name`` (``"a"`` … ``"e"``, ``"fetch"``) with a seed (an integer ≥ 0)."""
    check_int(seed, "seed", 0)
    return SCENES.build(name, ("seed",), seed=seed, **options)


ENV_ROBOT = {"a": "planar2", "b": "planar2", "c": "planar7", "d": "planar7", "e": "planar7"}
C_LAYOUT_SEED = 2022


@register_scene("a")
def env_a(seed: int = 0) -> Scene:
    """planar2 and one fixed axis-aligned 0.3 m square (the seed is ignored)."""
    robot = load_robot("planar2")
    return Scene(robot, (square((0.6, 0.45), 0.3),), name="a", seed=seed)


@register_scene("b")
def env_b(seed: int = 0) -> Scene:
    """planar2 and one 0.3 m square, centre uniform in the disc of radius 1.3 m, any rotation."""
    robot = load_robot("planar2")
    rng = np.random.default_rng(seed)

    def draw(rng) -> np.ndarray:
        r, phi = 1.3 * np.sqrt(rng.uniform()), rng.uniform(0, 2 * np.pi)
        return square((r * np.cos(phi), r * np.sin(phi)), 0.3, rng.uniform(0, np.pi / 2))

    return Scene(robot, tuple(place_clear(draw, 1, robot, rng)), name="b", seed=seed)


@register_scene("c")
def env_c(seed: int = 0) -> Scene:
    """planar7 and the fixed layout of 20 squares (env d drawn with seed 2022; seed ignored)."""
    robot = load_robot("planar7")
    return Scene(robot, tuple(random_squares(robot, C_LAYOUT_SEED)), name="c", seed=seed)


@register_scene("d")
def env_d(seed: int = 0) -> Scene:
    """planar7 and 20 squares of 0.2 m, centres uniform in [-2, 2]², rotations uniform."""
    robot = load_robot("planar7")
    return Scene(robot, tuple(random_squares(robot, seed)), name="d", seed=seed)


@register_scene("e")
def env_e(seed: int = 0) -> Scene:
    """planar7 and 5 random α-shapes with centres uniform in [-1.8, 1.8]²."""
    robot = load_robot("planar7")
    rng = np.random.default_rng(seed)
    shapes = place_clear(lambda g: random_alpha_shape(g) + g.uniform(-1.8, 1.8, 2), 5, robot, rng)
    return Scene(robot, tuple(shapes), name="e", seed=seed)


# -------------------------------------------------------------------- from configuration
def scene_from_config(cfg: dict, base_dir: str | Path | None = None) -> Scene:
    """Scene from a problem TOML mapping: ``[robot]``, optional ``[scene]``, ``[[obstacles]]``.

    ``[robot] name`` (plus options such as ``gripper``) selects a shipped robot, ``[robot]
    urdf`` (plus ``joints`` …, :mod:`gdnplan.robot_file`) loads one from a URDF file, relative
    paths starting at ``base_dir`` (the problem file's folder; the current directory when
    None); ``[scene] generator`` and ``seed`` draw generated obstacles; each ``[[obstacles]]
    polygon`` adds one polygon.
    """
    robot_cfg = cfg.get("robot", {})
    scene_cfg = cfg.get("scene", {})
    if not isinstance(robot_cfg, dict) or not isinstance(scene_cfg, dict):
        raise ProblemFileError("[robot] and [scene] must be tables")
    obstacles = []
    name, seed, info = "custom", None, {}
    base = None
    if "generator" in scene_cfg:
        seed = scene_cfg.get("seed", 0)
        if isinstance(seed, bool) or not isinstance(seed, int) or seed < 0:
            raise ProblemFileError(f"[scene] seed: expected an integer ≥ 0, got {seed!r}")
        generator = scene_cfg["generator"]
        if not isinstance(generator, str):
            raise ProblemFileError(f"[scene] generator: expected a name, got {generator!r}")
        if generator in SCENES:  # an unknown name is make_scene's UnknownNameError
            allowed = SCENE_KEYS | scene_options(generator)
            no_unknown_keys(scene_cfg, allowed, f"[scene] (generator {generator!r})")
        options = {k: v for k, v in scene_cfg.items() if k not in ("generator", "seed")}
        base = call_reporting("[scene]", make_scene, generator, seed=seed, **options)
        obstacles += list(base.obstacles)
        name, info = base.name, dict(base.info)
    elif scene_cfg:
        keys = sorted(scene_cfg)
        raise ProblemFileError(
            f"[scene] generator: missing; {keys} need a generator name (e.g. d)", schema=True
        )
    if "urdf" in robot_cfg:
        from .robot_file import robot_from_table

        robot = robot_from_table(robot_cfg, base_dir)
    elif "name" in robot_cfg:
        options = {k: v for k, v in robot_cfg.items() if k != "name"}
        if not isinstance(robot_cfg["name"], str):
            raise ProblemFileError(f"[robot] name: expected a name, got {robot_cfg['name']!r}")
        if robot_cfg["name"] in robot_names():  # an unknown name is load_robot's error
            allowed = ROBOT_KEYS | robot_options(robot_cfg["name"])
            no_unknown_keys(robot_cfg, allowed, f"[robot] (name {robot_cfg['name']!r})")
        robot = call_reporting("[robot]", load_robot, robot_cfg["name"], **options)
    elif base is not None and not robot_cfg:
        robot = base.robot
    else:
        raise ProblemFileError(
            '[robot] name: missing; give a robot name (e.g. planar7) or urdf = "arm.urdf"',
            schema=True,
        )
    extra = cfg.get("obstacles", [])
    if not isinstance(extra, list):
        raise ProblemFileError("[[obstacles]]: expected an array of tables with a polygon each")
    for i, item in enumerate(extra):
        if not isinstance(item, dict) or "polygon" not in item:
            raise ProblemFileError(
                f"[[obstacles]] #{i}: missing 'polygon = [[x, y], ...]'", schema=True
            )
        no_unknown_keys(item, OBSTACLE_KEYS, f"[[obstacles]] #{i}")
        try:
            obstacles.append(as_polygon(item["polygon"], f"obstacles[{i}].polygon"))
        except InputError as e:
            raise ProblemFileError(str(e)) from e
    return call_reporting(
        "[[obstacles]]", Scene, robot, tuple(obstacles), name=name, seed=seed, info=info
    )


__all__ = [  # re-exported too: scene_checks (MAX_OBSTACLES, MAX_PARTS, coordinate_bound, …)
    "C_LAYOUT_SEED",
    "ENV_ROBOT",
    "KINDS",
    "MAX_OBSTACLES",
    "MAX_PARTS",
    "OBSTACLE_KEYS",
    "ROBOT_KEYS",
    "SCENE_KEYS",
    "Scene",
    "check_scene",
    "clear_of_base",
    "coordinate_bound",
    "env_a",
    "env_b",
    "env_c",
    "env_d",
    "env_e",
    "make_scene",
    "no_unknown_keys",
    "random_alpha_shape",
    "register_scene",
    "scene_from_config",
    "scene_names",
    "scene_options",
]
