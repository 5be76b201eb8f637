"""Whether GraphDistNet-3D weights fit a scene: the scenes a card's network was trained on, and
one InputError (naming the difference and the fix) for a scene outside them, raised before any
distance is computed.

A learned distance holds only on its training distribution. Outside it the estimate is not a
little off but wrong by decimetres, and wrong on the unsafe side: the network reads obstacles
as the nodes of their graphs (a box's 8 corners), so a large box — a table, a storage wall —
whose corners are far from the arm looks far away where the arm touches its face; a robot with
a held object has a shape the network never saw. (Every plan is
still certified by coal, so the planner would fail rather than return a colliding path, but a
model that answers ``distance`` must not answer wrongly.) The rules, from the card:

* ``"robot"``: the scene's robot must have that name, and its link geometry must be the
  built-in robot's (:func:`gdnplan.arm3d.load_robot3d`): the same robot-graph nodes (count and
  bodies) at the card's ``rim``, none moved by more than :data:`NODE_TOL` — the gripper's
  finger travel, so another finger opening (``[robot] finger``) passes: the graph is built from
  the scene's robot, so its finger nodes sit where the fingers are, and the learned distance
  measured no less accurate with the fingers open (docs/decisions.md, s6-plan3dgdn). A held
  object (:func:`gdnplan.arm3d.hold`) adds a shape and is refused.
* ``"env"``: the training environment; :data:`TRAINED` says which obstacles it drew. For
  ``ur5e_boxes`` (:mod:`gdnplan.data.samples3d`): axis-aligned boxes with sides within
  ``BOX_SIZE`` and centres at least ``BASE_CLEARANCE`` from the base's vertical axis, the
  defaults of :func:`gdnplan.arm3d.random_boxes` (within :data:`GEOMETRY_TOL`). Any other
  shape — sphere, cylinder, capsule, mesh, a point cloud's octree — is refused. A card naming
  an environment not in :data:`TRAINED` is refused (its training scenes are unknown here).
  For ``ur5e_storage`` (:mod:`gdnplan.data.samples_storage3d`): boxes turned about the
  vertical only (the table, the storage's walls, the stick), none longer than the table, and
  the robot may hold a box stick within :func:`~gdnplan.arm3d.storage3d.random_storage`'s
  ranges (its nodes are then left out of the robot comparison).
* A card without ``"env"`` or ``"robot"`` (a network built in code, not trained weights)
  makes no claim and is not checked on that point; every scene needs an obstacle.
"""

from __future__ import annotations

from dataclasses import dataclass

import coal
import numpy as np

from ...arm3d import Obstacle3D, Scene3D, load_robot3d
from ...arm3d.held import HELD_LINK
from ...arm3d.scene3d import BASE_CLEARANCE, BOX_SIZE
from ...arm3d.storage3d import STICK_LENGTH, STICK_WIDTH, TABLE
from ...errors import InputError
from ...graph3d import robot_graph3d

GEOMETRY_TOL = 1e-3  # m: box sides and clearances within this count as trained
NODE_TOL = 0.03  # m: robot-graph nodes moved at most this from the built-in robot's (fingers)
COAL = "use collision='coal' (exact) or weights trained on such scenes"


@dataclass(frozen=True)
class Boxes:
    """Training obstacles: axis-aligned boxes with sides in ``size`` (m), centres at least
    ``base_clearance`` (m) from the base's vertical axis."""

    size: tuple[float, float]
    base_clearance: float

    def describe(self) -> str:
        lo, hi = self.size
        return (
            f"axis-aligned boxes with sides {lo:g}–{hi:g} m, centres ≥ {self.base_clearance:g} m "
            "from the base axis"
        )

    def misfit(self, obstacle: Obstacle3D) -> str | None:
        """Why ``obstacle`` is outside the training boxes (None: inside)."""
        shape = obstacle.shape
        if not isinstance(shape, coal.Box):
            return f"is a {shape_kind(shape)}"
        rot = np.abs(np.asarray(obstacle.pose.getRotation()))
        if not np.allclose(np.sort(rot, axis=1), [0.0, 0.0, 1.0], atol=1e-6):
            return "is a rotated box"
        sides = 2.0 * np.asarray(shape.halfSide)
        lo, hi = self.size
        if sides.min() < lo - GEOMETRY_TOL or sides.max() > hi + GEOMETRY_TOL:
            return f"is a box of sides {' × '.join(f'{s:.3g}' for s in sides)} m"
        centre = np.asarray(obstacle.pose.getTranslation())
        if np.hypot(centre[0], centre[1]) < self.base_clearance - GEOMETRY_TOL:
            return f"has its centre {np.hypot(centre[0], centre[1]):.3g} m from the base axis"
        return None


@dataclass(frozen=True)
class StorageBoxes:
    """Training obstacles of ``ur5e_storage``: the table, a storage's walls and the stick —
    boxes turned about the vertical axis only, no side longer than ``max_side`` (m), centres
    at least ``base_clearance`` (m) from the base's vertical axis; and the robot may hold a
    box stick (the fetch's) of length within ``stick_length`` and width ``stick_width`` (m)."""

    max_side: float
    base_clearance: float
    stick_length: tuple[float, float]
    stick_width: tuple[float, float]

    def describe(self) -> str:
        return (
            f"boxes turned about the vertical only, sides ≤ {self.max_side:g} m, centres ≥ "
            f"{self.base_clearance:g} m from the base axis (a table and storages)"
        )

    def misfit(self, obstacle: Obstacle3D) -> str | None:
        """Why ``obstacle`` is outside the training obstacles (None: inside)."""
        shape = obstacle.shape
        if not isinstance(shape, coal.Box):
            return f"is a {shape_kind(shape)}"
        rot = np.asarray(obstacle.pose.getRotation())
        if not np.allclose(np.abs(rot[2]), [0.0, 0.0, 1.0], atol=1e-6):
            return "is a box tilted off the vertical"
        sides = 2.0 * np.asarray(shape.halfSide)
        if sides.max() > self.max_side + GEOMETRY_TOL:
            return f"is a box of sides {' × '.join(f'{s:.3g}' for s in sides)} m"
        centre = np.asarray(obstacle.pose.getTranslation())
        if np.hypot(centre[0], centre[1]) < self.base_clearance - GEOMETRY_TOL:
            return f"has its centre {np.hypot(centre[0], centre[1]):.3g} m from the base axis"
        return None

    def held_misfit(self, shape: coal.CollisionGeometry) -> str | None:
        """Why a held ``shape`` is not a trained stick (None: it is one)."""
        if not isinstance(shape, coal.Box):
            return f"a held {shape_kind(shape)}"
        w1, w2, length = np.sort(2.0 * np.asarray(shape.halfSide))
        lo, hi = self.stick_length
        wlo, whi = self.stick_width
        t = GEOMETRY_TOL
        if not (lo - t <= length <= hi + t and wlo - t <= w1 <= w2 <= whi + t):
            return f"a held box of sides {w1:.3g} × {w2:.3g} × {length:.3g} m"
        return None


TRAINED = {  # environment -> its obstacles
    "ur5e_boxes": Boxes(BOX_SIZE, BASE_CLEARANCE),
    "ur5e_storage": StorageBoxes(
        max(TABLE[0][1] - TABLE[0][0], TABLE[1][1] - TABLE[1][0]),
        BASE_CLEARANCE,
        STICK_LENGTH,
        STICK_WIDTH,
    ),
}


def shape_kind(shape: coal.CollisionGeometry) -> str:
    """A coal shape's kind for messages ("box", "sphere", "point cloud (octree)", …)."""
    if isinstance(shape, coal.OcTree):
        return "point cloud (octree)"
    if isinstance(shape, coal.ConvexBase):
        return "convex mesh"
    return type(shape).__name__.lower()


def check_fits3d(card: dict, rim: int, scene: object) -> None:
    """InputError unless ``scene`` lies within what ``card``'s weights were trained on (module
    docstring); ``rim``: the network's robot-graph rim points."""
    if not isinstance(scene, Scene3D):
        raise InputError(
            f"scene: GraphDistNet-3D weights take 3-D scenes, got a {type(scene).__name__}; use "
            "planar weights (e.g. 'd') for a planar scene"
        )
    env = card.get("env")
    trained = TRAINED.get(env) if env is not None else None
    if env is not None and trained is None:
        raise InputError(
            f"weights: the card's training environment {env!r} is not one whose scenes gdnplan "
            f"knows ({', '.join(TRAINED)}); {COAL}"
        )
    robot = card.get("robot")
    if robot is not None:
        _check_robot(str(robot), rim, scene, getattr(trained, "held_misfit", None))
    if not scene.obstacles:
        raise InputError("scene.obstacles: GraphDistNet-3D needs at least one obstacle")
    if trained is None:
        return
    for i, obstacle in enumerate(scene.obstacles):
        why = trained.misfit(obstacle)
        if why is not None:
            raise InputError(
                f"scene.obstacles[{i}] ({obstacle.name!r}) {why}: these weights were trained on "
                f"{trained.describe()} (environment {env}) and their distance to other "
                f"obstacles can be wrong by decimetres; {COAL}"
            )


def _check_robot(robot: str, rim: int, scene: Scene3D, held_misfit=None) -> None:
    """The robot rules (module docstring); ``held_misfit``: the environment's test of a held
    shape (None: holding is refused), whose nodes are then left out of the comparison."""
    have = scene.robot
    if have.name != robot:
        raise InputError(
            f"scene: these weights were trained for robot {robot!r}, not {have.name!r}; {COAL}"
        )
    trained, graph = robot_graph3d(load_robot3d(robot), rim), robot_graph3d(have, rim)
    keep = np.ones(graph.n_nodes, bool)
    what = None
    if held_misfit is not None and HELD_LINK in have.links:
        carried = [s.shape for s in have.shapes if s.link == HELD_LINK]
        what = held_misfit(carried[0]) if len(carried) == 1 else f"{len(carried)} held shapes"
        keep = graph.link != have.links.index(HELD_LINK)
    same_nodes = int(keep.sum()) == trained.n_nodes
    if what is None and (not same_nodes or not np.array_equal(graph.body[keep], trained.body)):
        what = f"{graph.n_nodes} graph nodes against {trained.n_nodes}"
    elif what is None:
        moved = float(np.linalg.norm(graph.local[keep] - trained.local, axis=1).max())
        if moved > NODE_TOL:
            what = f"link nodes moved up to {moved:.3g} m"
    if what is not None:
        held = have.info.get("held")
        cause = f"it holds {held!r}" if held else "other link geometry"
        raise InputError(
            f"scene.robot: these weights were trained on the built-in {robot}'s link geometry; "
            f"this {robot}'s differs ({cause}: {what}), which the learned distance would not "
            f"see; {COAL}"
        )


__all__ = [
    "GEOMETRY_TOL",
    "NODE_TOL",
    "TRAINED",
    "Boxes",
    "StorageBoxes",
    "check_fits3d",
    "shape_kind",
]
