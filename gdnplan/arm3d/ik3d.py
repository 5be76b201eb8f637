"""End-effector pose IK of a 3-D robot on Pinocchio: damped least squares on the SE(3) error.

The target is a world pose ᵒM_d of the robot's tool frame f (:func:`tool_frame`: the UR5e's
gripper TCP between the fingers, the Panda's ``panda_hand_tcp``, the UR5's ``tool0``), given as
a position (3,) in m and a rotation (a quaternion (x, y, z, w) or a 3×3 matrix,
:func:`gdnplan.arm3d.shapes.as_rotation`). With ᶠM_d(q) = ᵒM_f(q)⁻¹ ᵒM_d the pose error in the
tool frame and e(q) = log₆(ᶠM_d) ∈ ℝ⁶ its twist (linear part in m, angular part in rad), one
step of damped least squares is

    J_e = −Jlog₆(ᶠM_d⁻¹) J_f(q)                                 (6, dof), J_f in LOCAL axes
    Δq = −J_eᵀ (J_e J_eᵀ + λ² I)⁻¹ e,     q ← clip(q + Δq, lower, upper)

until |e_lin| ≤ ``position_tol`` and |e_ang| ≤ ``rotation_tol``. The first attempt starts at the
reference configuration, the others at uniform random configurations within the joint limits.
A converged q is moved joint by joint by multiples of 2π towards the reference (staying within
the limits: the same pose) and kept when its coal signed distance
(:class:`gdnplan.arm3d.distance3d.Checker3D`, obstacles and self-collision) is at least
``margin``; :func:`solve_pose_ik` returns the kept solution closest to the reference (Euclidean
in rad).

:func:`cartesian_path` follows a sequence of tool positions at one rotation by continuation:
each point is solved from the previous solution (its nearest), and a joint jump larger than
``max_jump`` (a branch switch, not a continuous motion) fails it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin
from numpy.typing import ArrayLike

from ..errors import InfeasibleProblemError, InputError
from ..limits import check_number
from ..robot_checks import make_rng
from .distance3d import checker3d
from .ik3d_checks import MAX_POINTS, MIN_TOL, check_ik_settings, check_positions
from .robot3d import Robot3D
from .scene3d import Scene3D, check_robot3d
from .shapes import as_rotation, as_vector

TOOL_FRAMES = {"ur5e": "gripper_tcp", "panda": "panda_hand_tcp", "ur5": "tool0"}
DAMPING = 1e-3  # λ of the damped least squares (m or rad)
MAX_STEP = 0.5  # rad: largest joint change of one step (|Δq|∞, scaled down)
NEAR = (
    1e-3,
    1e-2,
)  # m, rad: a closest miss within these is "tolerance not met", not "out of reach"


@dataclass(frozen=True)
class PoseIK:
    """A pose-IK solution.

    Attributes:
        q: (dof,) joint angles (rad) within the limits.
        position_error: |p_f(q) − p_d| (m); rotation_error: angle of R_f(q)ᵀ R_d (rad).
        distance: coal signed distance at q (m, obstacles and self-collision).
        attempts: start configurations tried; solutions: converged collision-free ones found.
    """

    q: np.ndarray
    position_error: float
    rotation_error: float
    distance: float
    attempts: int
    solutions: int


def tool_frame(robot: Robot3D) -> str:
    """The name of the robot's tool frame: ``robot.info["tool_frame"]``, else the built-in's
    (:data:`TOOL_FRAMES`), else the last frame of the model."""
    check_robot3d(robot)
    name = robot.info.get("tool_frame") or TOOL_FRAMES.get(robot.name)
    return name if name is not None else robot.model.frames[len(robot.model.frames) - 1].name


def _frame_id(robot: Robot3D, frame: str | None) -> int:
    name = tool_frame(robot) if frame is None else frame
    if not isinstance(name, str) or not robot.model.existFrame(name):
        raise InputError(f"frame: {name!r} is not a frame of {robot.name}")
    return robot.model.getFrameId(name)


def pose_target(position, rotation=None, name: str = "target") -> pin.SE3:
    """A world pose from a position (3,) in m and a rotation (quaternion xyzw or 3×3 matrix);
    InputError naming ``name`` for a non-finite position or a rotation that is not one."""
    p = as_vector(position, 3, f"{name}.position")
    return pin.SE3(as_rotation(rotation, f"{name}.rotation"), p)


def frame_pose(robot: Robot3D, q, frame: str | None = None) -> pin.SE3:
    """World pose of ``frame`` (default: the tool frame) at one configuration q (dof,)."""
    fid = _frame_id(robot, frame)
    q = robot.check_q(q)[0]
    pin.framesForwardKinematics(robot.model, robot.data, q)
    return pin.SE3(robot.data.oMf[fid])


def _errors(current: pin.SE3, target: pin.SE3) -> tuple[float, float]:
    """(position error m, rotation angle rad) between two poses."""
    pos = float(np.linalg.norm(current.translation - target.translation))
    cos = (np.trace(current.rotation.T @ target.rotation) - 1.0) / 2.0
    return pos, float(np.arccos(np.clip(cos, -1.0, 1.0)))


def _dls(
    robot: Robot3D,
    fid: int,
    target: pin.SE3,
    q0: np.ndarray,
    iterations: int,
    position_tol: float,
    rotation_tol: float,
) -> tuple[np.ndarray | None, tuple[float, float]]:
    """Damped least squares from q0 (dof,): (the converged q within the limits, or None;
    (|e_lin| m, |e_ang| rad) at the last iterate)."""
    model, data = robot.model, robot.data
    q = np.clip(np.asarray(q0, dtype=float), robot.lower, robot.upper)
    eye = np.eye(6)
    miss = (np.inf, np.inf)
    for _ in range(iterations):
        pin.framesForwardKinematics(model, data, q)
        err_pose = data.oMf[fid].actInv(target)
        err = pin.log6(err_pose).vector
        miss = (float(np.linalg.norm(err[:3])), float(np.linalg.norm(err[3:])))
        if miss[0] <= position_tol and miss[1] <= rotation_tol:
            return q, miss
        jac = pin.computeFrameJacobian(model, data, q, fid, pin.ReferenceFrame.LOCAL)
        jac = -pin.Jlog6(err_pose.inverse()) @ jac
        step = -jac.T @ np.linalg.solve(jac @ jac.T + DAMPING**2 * eye, err)
        step *= min(1.0, MAX_STEP / max(float(np.abs(step).max()), 1e-12))
        q = np.clip(q + step, robot.lower, robot.upper)
    return None, miss


def nearest_equivalent(robot: Robot3D, q: np.ndarray, reference: np.ndarray) -> np.ndarray:
    """q with each joint shifted by a multiple of 2π towards ``reference``, within the limits."""
    k = np.round((reference - q) / (2 * np.pi))
    shifted = q + 2 * np.pi * k
    ok = (shifted >= robot.lower - 1e-12) & (shifted <= robot.upper + 1e-12)
    return np.where(ok, shifted, q)


def solve_pose_ik(
    scene: Scene3D | Robot3D,
    position: ArrayLike,
    rotation: ArrayLike | None = None,
    reference: ArrayLike | None = None,
    frame: str | None = None,
    margin: float = 0.0,
    restarts: int = 64,
    solutions: int = 8,
    seed: int = 0,
    iterations: int = 200,
    position_tol: float = 1e-5,
    rotation_tol: float = 1e-4,
) -> PoseIK:
    """Joint angles putting ``frame`` (default: the tool frame) at a world pose, collision-free.

    Args:
        scene: the robot and its obstacles (a bare Robot3D checks self-collision only).
        position: (3,) target position (m); rotation: quaternion (x, y, z, w) or 3×3 matrix
            (None: identity).
        reference: (dof,) the configuration the solution should be close to (default: the
            middle of the limits); also the first start.
        margin: smallest coal signed distance (m) a solution must keep.
        restarts: start configurations tried at most (the reference, then random ones);
            solutions: stop after this many distinct collision-free solutions.
        seed: of the random starts. iterations: DLS steps per start.
        position_tol (m), rotation_tol (rad): convergence of |e_lin|, |e_ang|, each finite and
            ≥ :data:`MIN_TOL` (10⁻¹²: float64 forward kinematics of a ~1 m arm is exact to
            ~10⁻¹⁵, and the DLS reaches ~10⁻¹⁴; smaller tolerances are refused).

    Raises:
        InputError: a position that is not 3 finite numbers, a rotation that is not a rotation,
            an unknown frame, a reference of the wrong shape.
        InfeasibleProblemError: no start converged (the message gives the closest miss: within
            :data:`NEAR` it says the tolerance was not met, else that the pose is out of
            reach), or every converged solution is closer than ``margin`` to an obstacle or the
            robot itself.
    """
    scene = scene if isinstance(scene, Scene3D) else Scene3D(scene)
    robot = scene.robot
    target = pose_target(position, rotation)
    fid = _frame_id(robot, frame)
    check_ik_settings(margin, restarts, solutions, iterations, position_tol, rotation_tol)
    mid = (robot.lower + robot.upper) / 2
    ref = mid if reference is None else robot.check_q(reference, "reference")[0]
    rng = make_rng(seed)
    checker = checker3d(scene)
    found: list[tuple[np.ndarray, float]] = []
    converged = 0
    attempts = 0
    closest = (np.inf, np.inf)
    for attempts in range(1, restarts + 1):
        start = ref if attempts == 1 else robot.random_configurations(1, rng)[0]
        q, miss = _dls(robot, fid, target, start, iterations, position_tol, rotation_tol)
        if q is None:
            closest = min(closest, miss, key=lambda m: max(m[0] / NEAR[0], m[1] / NEAR[1]))
            continue
        converged += 1
        q = nearest_equivalent(robot, q, ref)
        d = float(checker.evaluate(q).distance[0])
        if d >= margin and not any(np.allclose(q, f, atol=1e-3) for f, _ in found):
            found.append((q, d))
            if len(found) >= solutions:
                break
    if not found:
        where = f"position {np.round(target.translation, 4).tolist()} m"
        if converged == 0:
            why = _miss_text(closest, position_tol, rotation_tol)
            raise InfeasibleProblemError(
                f"goal pose: no IK solution for {tool_frame(robot) if frame is None else frame} "
                f"at {where} in {attempts} starts; {why}"
            )
        raise InfeasibleProblemError(
            f"goal pose: {converged} IK solutions at {where}, none with clearance ≥ {margin} m"
        )
    q, d = min(found, key=lambda f: float(np.linalg.norm(f[0] - ref)))
    pos, ang = _errors(frame_pose(robot, q, frame), target)
    return PoseIK(q, pos, ang, d, attempts, len(found))


def _miss_text(closest: tuple[float, float], position_tol: float, rotation_tol: float) -> str:
    """Why no start converged, from the closest miss (m, rad)."""
    pos, ang = closest
    text = f"closest: {pos:.3g} m, {ang:.3g} rad"
    if pos <= NEAR[0] and ang <= NEAR[1]:
        return (
            f"the tolerance was not met ({text}; position_tol {position_tol:g} m, rotation_tol "
            f"{rotation_tol:g} rad): raise the tolerances or iterations"
        )
    return f"the pose is out of reach, or needs more restarts or iterations ({text})"


def cartesian_path(
    scene: Scene3D | Robot3D,
    q0,
    positions,
    rotation,
    margin: float = 0.0,
    max_jump: float = 0.3,
    frame: str | None = None,
) -> np.ndarray:
    """(K + 1, dof) joint path q0, q_1 … q_K through tool ``positions`` (K, 3) (m) at one
    ``rotation``, each q_k the IK solution nearest q_{k−1} with clearance ≥ ``margin`` (m).

    ``positions``: one point (3,) or K in 1 … :data:`MAX_POINTS` points (K, 3), finite (m);
    ``rotation``: a quaternion (x, y, z, w) or 3×3 rotation matrix; ``margin``: finite (m);
    ``max_jump``: finite and > 0 (rad); ``frame`` a frame of the robot (None: the tool frame);
    q0 (dof,) rad. InputError naming the argument otherwise, before any IK is solved.
    Raises InfeasibleProblemError naming the point when it has no clear solution within
    ``max_jump`` (rad, largest joint change) of the previous one.
    """
    scene = scene if isinstance(scene, Scene3D) else Scene3D(scene)
    q = [scene.robot.check_q(q0, "q0")[0]]
    pts = check_positions(positions)
    rotation = as_rotation(rotation, "rotation")
    check_number(margin, "margin", -np.inf)
    check_number(max_jump, "max_jump", 0.0, strict=True)
    _frame_id(scene.robot, frame)
    for k, p in enumerate(pts):
        sol = None
        for restarts in (1, 8):
            try:
                sol = solve_pose_ik(
                    scene, p, rotation, q[-1], frame, margin, restarts, solutions=1, seed=k
                )
            except InfeasibleProblemError:
                continue
            if np.abs(sol.q - q[-1]).max() <= max_jump:
                break
            sol = None
        if sol is None:
            raise InfeasibleProblemError(
                f"cartesian path: point {k + 1}/{len(pts)} {np.round(p, 4).tolist()} m has no "
                f"IK solution with clearance ≥ {margin} m within {max_jump} rad of the last"
            )
        q.append(sol.q)
    return np.array(q)


__all__ = [  # MAX_POINTS, MIN_TOL: re-exported from ik3d_checks
    "MAX_POINTS",
    "MIN_TOL",
    "TOOL_FRAMES",
    "PoseIK",
    "cartesian_path",
    "frame_pose",
    "nearest_equivalent",
    "pose_target",
    "solve_pose_ik",
    "tool_frame",
]
