"""Scenes of the 3-D environment ``ur5e_storage``: the fetch's table and a random storage at a
random placement, with the UR5e in one of the fetch's two robot variants.

Scene ``scene_seed`` draws, from an rng seeded by (scene_seed, 11), a storage and stick
(:func:`gdnplan.arm3d.storage3d.random_storage`) and a placement
(:func:`~gdnplan.arm3d.storage3d.random_placement`), redrawn until the storage stands on the
table, and a variant, each with probability 1/2:

* ``OPEN`` (0): the fingers open (``OPEN_FINGER`` m each); obstacles: the table, the storage's
  boxes and the stick resting on its shelf (the fetch's ``open`` scene);
* ``HOLDING`` (1): the fingers closed on the stick, which is a shape of the robot
  (:func:`gdnplan.arm3d.hold`); obstacles: the table and the storage (the ``holding`` scene).

These are :func:`gdnplan.arm3d.fetch3d_scene.fetch3d_scenes` of the drawn storage and
placement. Shard arrays beside q, d, grad, scene, scene_seed (:mod:`.samples3d`):

============ =================== ==========================================
storage      (S, 13) float64     the Storage3D fields in declaration order (m)
placement    (S, 3) float64      x, y (m), yaw (rad) of the storage
variant      (S,) int8           OPEN or HOLDING
============ =================== ==========================================
"""

from __future__ import annotations

from dataclasses import astuple, fields
from functools import lru_cache

import numpy as np

from ..arm3d import Robot3D, Scene3D
from ..arm3d.fetch3d_scene import fetch3d_scenes
from ..arm3d.storage3d import Placement, Storage3D, on_table, random_placement, random_storage
from ..errors import InputError

OPEN, HOLDING = 0, 1
VARIANTS = {OPEN: "open", HOLDING: "holding"}  # variant -> fetch3d_scenes key
N_STORAGE_FIELDS = len(fields(Storage3D))


def storage_draw(scene_seed: int) -> tuple[Storage3D, Placement, int]:
    """The storage, placement and variant of scene ``scene_seed`` (module docstring)."""
    rng = np.random.default_rng([int(scene_seed), 11])
    for _ in range(1000):
        storage, placement = random_storage(rng), random_placement(rng)
        if on_table(storage, placement):
            return storage, placement, int(rng.integers(2))
    raise InputError(f"scene_seed: {scene_seed} drew no storage on the table")


def storage_row(storage: Storage3D, placement: Placement) -> tuple[np.ndarray, np.ndarray]:
    """The shard rows (13,), (3,) of a storage and its placement."""
    return np.array(astuple(storage), float), np.array([placement.x, placement.y, placement.yaw])


def storage_scene_of(storage_row_: np.ndarray, placement_row: np.ndarray, variant: int) -> Scene3D:
    """The Scene3D (robot with its self pairs) of a shard's scene row."""
    return _scene(tuple(map(float, storage_row_)), tuple(map(float, placement_row)), int(variant))


@lru_cache(maxsize=256)
def _scene(storage: tuple, placement: tuple, variant: int) -> Scene3D:
    scenes = fetch3d_scenes(Storage3D(*storage), Placement(*placement))
    return scenes[VARIANTS[variant]]


def without_self_pairs(robot: Robot3D) -> Robot3D:
    """``robot`` without self-collision pairs (labels are robot–obstacle)."""
    return Robot3D(robot.name, robot.model, robot.shapes, np.zeros((0, 2), int), {}, robot.info)


def storage_scenes(seeds: np.ndarray) -> tuple[dict, list[Scene3D]]:
    """The shard arrays (module docstring) of scenes ``seeds`` (S,) and their labelling scenes
    (the robot without self pairs)."""
    rows, scenes = [], []
    for s in seeds:
        storage, placement, variant = storage_draw(int(s))
        st, pl = storage_row(storage, placement)
        rows.append((st, pl, variant))
        scene = storage_scene_of(st, pl, variant)
        scenes.append(Scene3D(without_self_pairs(scene.robot), list(scene.obstacles)))
    geometry = {
        "storage": np.array([r[0] for r in rows]).reshape(-1, N_STORAGE_FIELDS),
        "placement": np.array([r[1] for r in rows]).reshape(-1, 3),
        "variant": np.array([r[2] for r in rows], dtype=np.int8),
    }
    return geometry, scenes


__all__ = [
    "HOLDING",
    "OPEN",
    "VARIANTS",
    "storage_draw",
    "storage_scene_of",
    "storage_scenes",
    "without_self_pairs",
]
