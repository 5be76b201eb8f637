"""The 3-D fetch scene: the full UR5e, the table, the storage with the stick, and the fetch's
configurations from pose IK.

Two scenes share the table and the storage (:mod:`gdnplan.arm3d.storage3d`): ``open`` (the
fingers open, ``OPEN_FINGER`` m each; the stick an obstacle) and ``holding`` (the fingers
closed on the stick, which is a shape of the robot, :func:`gdnplan.arm3d.held.hold`, and no
obstacle). The configurations are :func:`gdnplan.arm3d.ik3d.solve_pose_ik` solutions of the
storage's tool poses, each with coal clearance ≥ ``MIN_CLEARANCE`` in its scene and nearest the
previous one along the fetch: q_home (open; reference: :data:`NOMINAL`, turned to the
storage) → q_pregrasp → q_grasp (open) → q_lift → q_out (holding). q_home must also be clear
holding the stick (the retreat ends there).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import InfeasibleProblemError, InputError
from ..limits import check_int
from ..ur5e.gripper import MAX_OPENING
from .builtin import ur5e3d
from .distance3d import checker3d
from .held import hold, stick
from .ik3d import cartesian_path, frame_pose, solve_pose_ik
from .scene3d import Scene3D
from .storage3d import (
    Placement,
    Storage3D,
    on_table,
    random_placement,
    random_storage,
    stick_obstacle,
    storage_obstacles,
    table_obstacle,
    tool_poses,
    tool_rotations,
)

MIN_CLEARANCE = 0.015  # m: every fetch configuration keeps this coal distance in its scene
OPEN_FINGER = MAX_OPENING / 2  # m: each finger's opening before the grasp
MAX_TRIES = 1000  # random storages drawn at most for one seed
# the UR5e's reference pose (rad): tool horizontal along +x, elbow up (shoulder_pan is turned)
NOMINAL = np.array([0.0, -1.9, 2.2, -0.3, 1.57, 0.0])
IK_RESTARTS = 48
LINE_STEP = 0.01  # m: tool positions of the straight lines (reach in, lift, bring out)
LIFT_STEP = 0.002  # m: tool positions of the lift (10 points)
LINE_MARGIN = 0.01  # m: clearance of the points of the reach-in and bring-out lines
CANONICAL_STORAGE = Storage3D(  # the planar canonical fetch layout (CANONICAL_FETCH) in 3-D
    depth=0.36,
    width=0.32,
    top=0.3225,
    wall=0.02,
    floor=0.02,
    entrance_width=0.185,
    entrance_low=0.025,
    entrance_high=0.205,
    shelf=0.1,
    inset=0.03,
    overhang=0.07,
    stick_length=0.25,
    stick_width=0.03,
)
CANONICAL_PLACEMENT = Placement(
    0.62, -0.2, 0.0
)  # to the side: the stick comes out clear of the base
CONFIGS = ("q_home", "q_pregrasp", "q_grasp", "q_lift", "q_out")


@dataclass(frozen=True)
class Fetch3D:
    """A 3-D fetch: the storage, its placement, the two scenes and the configurations.

    Attributes:
        seed: the seed that drew it (None: given by the caller).
        storage, placement: sizes and pose of the storage.
        scenes: ``open`` and ``holding`` Scene3D. q: the configurations (6,) of CONFIGS (rad).
        lines: the straight tool lines (:func:`fetch3d_configurations`), (K, 6) joint paths.
    """

    seed: int | None
    storage: Storage3D
    placement: Placement
    scenes: dict[str, Scene3D]
    q: dict[str, np.ndarray] = field(default_factory=dict)
    lines: dict[str, np.ndarray] = field(default_factory=dict)


def fetch3d_scenes(storage: Storage3D, placement: Placement) -> dict[str, Scene3D]:
    """The ``open`` and ``holding`` scenes of a storage at a placement."""
    fixed = [table_obstacle(), *storage_obstacles(storage, placement)]
    open_robot = ur5e3d(finger=OPEN_FINGER)
    held = hold(
        ur5e3d(finger=storage.stick_width / 2), *stick(storage.stick_length, storage.stick_width)
    )
    return {
        "open": Scene3D(open_robot, [*fixed, stick_obstacle(storage, placement)]),
        "holding": Scene3D(held, fixed),
    }


def _ik(scene: Scene3D, position, rotations, reference, margin: float) -> np.ndarray:
    """The clear IK solution over the tool rotations nearest the reference (or raise)."""
    best, error = None, None
    for rot in rotations:
        try:
            sol = solve_pose_ik(
                scene, position, rot, reference, margin=margin, restarts=IK_RESTARTS, solutions=4
            )
        except InfeasibleProblemError as e:
            error = e
            continue
        if best is None or np.linalg.norm(sol.q - reference) < np.linalg.norm(best - reference):
            best = sol.q
    if best is None:
        assert error is not None
        raise error
    return best


def _line(a: np.ndarray, b: np.ndarray, step: float = LINE_STEP) -> np.ndarray:
    """(K, 3) points from a (excluded) to b (included), at most ``step`` m apart."""
    k = max(1, int(np.ceil(np.linalg.norm(b - a) / step - 1e-9)))
    return a + np.linspace(0.0, 1.0, k + 1)[1:, None] * (b - a)


def fetch3d_configurations(
    storage: Storage3D, placement: Placement, scenes: dict[str, Scene3D] | None = None
) -> tuple[dict[str, np.ndarray], dict[str, np.ndarray]]:
    """The fetch's configurations and straight tool lines (module doc).

    Returns ``q`` (CONFIGS → (6,)) and ``lines``: ``reach_in`` (q_pregrasp → q_grasp, the tcp
    straight along x_S through the entrance), ``lift`` (q_grasp → q_lift, straight up) and
    ``bring_out`` (q_lift → q_out, straight back out), joint paths (K, 6) from
    :func:`cartesian_path` with points ≤ LINE_STEP (lift: LIFT_STEP) apart.
    InfeasibleProblemError naming the pose or line that has no clear IK solution (out of
    reach, or the entrance too tight).
    """
    scenes = scenes or fetch3d_scenes(storage, placement)
    poses = tool_poses(storage, placement)
    rotations = tool_rotations(placement)
    nominal = NOMINAL.copy()
    nominal[0] = np.arctan2(placement.y, placement.x)
    q: dict[str, np.ndarray] = {}
    try:
        q["q_home"] = _ik(scenes["open"], poses["home"], rotations, nominal, MIN_CLEARANCE)
        q["q_pregrasp"] = _ik(
            scenes["open"], poses["pregrasp"], rotations, q["q_home"], MIN_CLEARANCE
        )
    except InfeasibleProblemError as e:
        raise InfeasibleProblemError(f"fetch3d: {e}") from e
    rot = frame_pose(scenes["open"].robot, q["q_pregrasp"]).rotation
    lines = {}
    for name, state, a, b, margin, step in (
        ("reach_in", "open", "pregrasp", "grasp", LINE_MARGIN, LINE_STEP),
        ("lift", "holding", "grasp", "lift", 0.0, LIFT_STEP),
        ("bring_out", "holding", "lift", "out", LINE_MARGIN, LINE_STEP),
    ):
        q0 = lines[name_before(name)][-1] if lines else q["q_pregrasp"]
        try:
            path = cartesian_path(scenes[state], q0, _line(poses[a], poses[b], step), rot, margin)
        except InfeasibleProblemError as e:
            raise InfeasibleProblemError(f"fetch3d: {name}: {e}") from e
        lines[name] = path
    q["q_grasp"], q["q_lift"], q["q_out"] = (
        lines[n][-1] for n in ("reach_in", "lift", "bring_out")
    )
    for key, state in (("q_grasp", "open"), ("q_lift", "holding"), ("q_out", "holding")):
        if checker3d(scenes[state]).evaluate(q[key]).distance[0] < MIN_CLEARANCE:
            raise InfeasibleProblemError(f"fetch3d: {key} is closer than {MIN_CLEARANCE} m")
    if checker3d(scenes["holding"]).evaluate(q["q_home"]).distance[0] < MIN_CLEARANCE:
        raise InfeasibleProblemError("fetch3d: the home pose is not clear holding the stick")
    return q, lines


def name_before(line: str) -> str:
    """The line that ends where ``line`` starts."""
    return {"lift": "reach_in", "bring_out": "lift"}[line]


def fetch3d(seed: int = 0, placement: Placement | None = None, max_tries: int = 100) -> Fetch3D:
    """The 3-D fetch of ``seed``: 0 is the canonical storage (the planar canonical layout in
    3-D, 0.62 m in front of the base); other seeds draw a random storage and placement
    (:func:`random_storage`, :func:`random_placement`) until its configurations exist, at most
    ``max_tries`` draws. A given ``placement`` places the seed's storage there (no redraw):
    InputError when it is off the table, InfeasibleProblemError when out of reach.
    """
    check_int(seed, "seed", 0)
    check_int(max_tries, "max_tries", 1, MAX_TRIES)
    rng = np.random.default_rng(seed)
    error: InfeasibleProblemError | None = None
    for _ in range(1 if seed == 0 or placement is not None else max_tries):
        storage = CANONICAL_STORAGE if seed == 0 else random_storage(rng)
        where = placement or (CANONICAL_PLACEMENT if seed == 0 else random_placement(rng))
        if not on_table(storage, where):
            if placement is not None:
                raise InputError(f"placement: {where} puts the storage off the table")
            continue
        scenes = fetch3d_scenes(storage, where)
        try:
            q, lines = fetch3d_configurations(storage, where, scenes)
        except InfeasibleProblemError as e:
            error = e
            continue
        return Fetch3D(seed, storage, where, scenes, q, lines)
    if placement is not None or seed == 0:
        assert error is not None
        raise error
    raise InfeasibleProblemError(
        f"fetch3d: seed {seed}: no reachable storage in max_tries={max_tries} draws ({error})"
    )


__all__ = [
    "CANONICAL_PLACEMENT",
    "CANONICAL_STORAGE",
    "CONFIGS",
    "MIN_CLEARANCE",
    "Fetch3D",
    "fetch3d",
    "fetch3d_configurations",
    "fetch3d_scenes",
]
