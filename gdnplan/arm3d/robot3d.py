"""3-D robots from URDF files through Pinocchio: planning joints, coal link shapes, kinematics.

A :class:`Robot3D` is a Pinocchio model reduced to its planning joints (every other joint is
locked at a value) and the link collision geometry as coal shapes: URDF primitives stay coal
primitives (box, sphere, cylinder, capsule), meshes become their convex hulls
(:func:`gdnplan.arm3d.shapes.mesh_hull`: validated, a non-convex mesh logs a note). A shape
belongs to the URDF link that carries it and moves with that link's *body*: the planning joint
the link hangs from (0 = the fixed base). Configurations q are (n,) or (B, n) in radians, in the
reduced model's joint order (:attr:`Robot3D.joint_names`); continuous joints are planned within
[−π, π].

Kinematics (one configuration): the world placement of shape s is oMᵢ(q) · Mₛ with i its body
and Mₛ the fixed placement of the shape in the body's joint frame. The linear velocity of a
point p fixed on body i is v = Σ_j (J_v,j + ω_j × (p − oᵢ)) q̇_j, from Pinocchio's joint
Jacobian J = [J_v; J_ω] (6, n) of body i in the LOCAL_WORLD_ALIGNED frame (origin at the joint
oᵢ, world axes); :meth:`Robot3D.point_jacobian` returns J_p = J_v − [p − oᵢ]× J_ω (3, n).
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np
import pinocchio as pin

from ..errors import InputError, UnknownNameError
from ..limits import check_int, check_number
from ..robot import MAX_SAMPLES, as_batch
from ..robot_checks import one_q
from ..urdf_robot import RobotSpec, load_urdf
from ..urdf_robot.joint_limits import check_joint_limits
from ..urdf_robot.load import check_mimic, urdf_path
from ..urdf_robot.locking import lock_mimics, set_locked
from ..urdf_robot.spec import check_folders, check_locked, check_names
from .link_shape import LinkShape as LinkShape
from .link_shape import link_shape_from_geometry
from .pairs import contact_only_mask, self_collision_pairs


class Robot3D:
    """A 3-D arm: a reduced Pinocchio model, coal link shapes and self-collision pairs;
    immutable once built (its arrays are read-only, its attributes cannot be set).

    Attributes:
        name: the robot's name. model: the reduced ``pin.Model`` (nq = nv = dof).
        shapes: every link shape; links: names of the links with shapes (the per-link order).
        shape_link: (S,) index into ``links`` of each shape.
        self_pairs: (P, 2) shape indices of the self-collision pairs checked.
        contact_only: the link pairs (frozensets of two names) checked for contact only
            (signed distance ≥ 0, never the clearance margin; :mod:`gdnplan.arm3d.pairs`).
        self_contact_only: (P,) bool, True for the rows of ``self_pairs`` on those links.
        disabled: every unchecked link pair → its reason.
        lower, upper: (dof,) joint limits (rad).
    """

    def __init__(
        self,
        name: str,
        model: pin.Model,
        shapes: Sequence[LinkShape],
        self_pairs: np.ndarray,
        disabled: dict[frozenset[str], str],
        info: dict | None = None,
        contact_only=frozenset(),
    ):
        self.name = name
        self.model = model
        self.data = model.createData()
        self.shapes = tuple(shapes)
        for s in self.shapes:
            if not isinstance(s, LinkShape):
                raise InputError(f"shapes: expected LinkShape items, got {type(s).__name__}")
            if s.body >= model.njoints:
                raise InputError(
                    f"shapes: {s.name!r} hangs from body {s.body}, but the model has "
                    f"{model.njoints} joints (bodies 0 … {model.njoints - 1})"
                )
        self.links = tuple(dict.fromkeys(s.link for s in self.shapes))
        self.shape_link = np.array([self.links.index(s.link) for s in self.shapes], dtype=int)
        self.shape_body = np.array([s.body for s in self.shapes], dtype=int)
        self.self_pairs = np.asarray(self_pairs, dtype=int).reshape(-1, 2)
        if np.any(self.self_pairs < 0) or np.any(self.self_pairs >= len(self.shapes)):
            raise InputError(  # a negative index named another shape silently
                f"self_pairs: shape indices must lie in [0, {len(self.shapes) - 1}]"
            )
        self.disabled = dict(disabled)
        self.contact_only = frozenset(frozenset(p) for p in contact_only)
        self.self_contact_only = contact_only_mask(self.shapes, self.self_pairs, self.contact_only)
        self.lower = model.lowerPositionLimit.copy()
        self.upper = model.upperPositionLimit.copy()
        self.info = dict(info or {})
        self.joint_names = tuple(model.names[1:])
        for array in (self.shape_link, self.shape_body, self.self_pairs, self.lower, self.upper):
            array.flags.writeable = False
        self.self_contact_only.flags.writeable = False
        object.__setattr__(self, "_frozen", True)

    def __setattr__(self, name: str, value) -> None:
        """Immutable once built: the certificate's motion bounds and the checkers are cached
        per robot object (and ``load_robot3d`` hands every caller the same one)."""
        if getattr(self, "_frozen", False):
            raise AttributeError(
                f"Robot3D is immutable: build a new robot instead of setting {name!r}"
            )
        object.__setattr__(self, name, value)

    @property
    def dof(self) -> int:
        return int(self.model.nq)

    @property
    def n_links(self) -> int:
        return len(self.links)

    def check_q(self, q, name: str = "q") -> np.ndarray:
        """Joint angles as float64 (B, dof); InputError for a wrong shape, NaN or infinity."""
        return as_batch(q, self.dof, name)

    def within_limits(self, q, tol: float = 1e-9) -> np.ndarray:
        """(B,) True where every joint is within its limits (widened by ``tol`` ≥ 0)."""
        q, tol = self.check_q(q), check_number(tol, "tol")
        return np.all((q >= self.lower - tol) & (q <= self.upper + tol), axis=1)

    def random_configurations(self, n: int, rng: np.random.Generator) -> np.ndarray:
        """(n, dof) configurations drawn uniformly within the joint limits (n ≤ 10⁸)."""
        check_int(n, "n", 0, MAX_SAMPLES)
        if not isinstance(rng, np.random.Generator):
            raise InputError(f"rng: expected a numpy.random.Generator, got {type(rng).__name__}")
        return rng.uniform(self.lower, self.upper, size=(n, self.dof))

    # ---------------------------------------------------------------- kinematics
    # (each takes one configuration (dof,), checked by one_q: Pinocchio raised its own errors
    # for a wrong size, and numpy dropped a complex q's imaginary part)
    def body_placements(self, q: np.ndarray) -> np.ndarray:
        """(njoints, 4, 4) world placements of every body's joint frame at one q (dof,)."""
        pin.forwardKinematics(self.model, self.data, one_q(q, self.dof))
        return np.array([m.homogeneous for m in self.data.oMi])

    def shape_placements(self, q: np.ndarray) -> np.ndarray:
        """(S, 4, 4) world placements of every link shape at one configuration q (dof,)."""
        bodies = self.body_placements(q)
        local = np.array([s.placement for s in self.shapes]).reshape(-1, 4, 4)
        return bodies[self.shape_body] @ local

    def joint_jacobians(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Every body's joint Jacobian (njoints, 6, dof), LOCAL_WORLD_ALIGNED ([v; ω] of the
        joint origin in world axes), and the joint origins (njoints, 3) in m, at one q (dof,)."""
        pin.computeJointJacobians(self.model, self.data, one_q(q, self.dof))
        frame = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
        jac = np.array(
            [
                pin.getJointJacobian(self.model, self.data, j, frame)
                for j in range(self.model.njoints)
            ]
        )
        origins = np.array([m.translation for m in self.data.oMi])
        return jac, origins

    def point_jacobian(self, q: np.ndarray, body: int, point: np.ndarray) -> np.ndarray:
        """(3, dof) Jacobian ∂p/∂q of a world point (3,) fixed on ``body`` (a joint index,
        0 … njoints − 1) at one q (dof,)."""
        body = check_int(body, "body", 0, self.model.njoints - 1)
        point = one_q(point, 3, "point")
        jac, origins = self.joint_jacobians(q)
        return point_jacobians(jac[body][None], origins[body][None], point[None])[0]


def point_jacobians(jac: np.ndarray, origins: np.ndarray, points: np.ndarray) -> np.ndarray:
    """(k, 3, dof) point Jacobians J_v − [p − o]× J_ω from joint Jacobians (k, 6, dof), their
    origins (k, 3) and points (k, 3) on those bodies (world frame, m)."""
    r = points - origins
    jv, jw = jac[:, :3], jac[:, 3:]
    return jv + np.cross(jw, r[:, :, None], axisa=1, axisb=1, axisc=1)


# -------------------------------------------------------------------- loading
def robot3d_from_urdf(
    urdf: str | Path,
    package_dirs: Sequence[str | Path] = (),
    joints: Sequence[str] | None = None,
    locked: dict[str, float] | None = None,
    srdf: str | Path | None = None,
    name: str | None = None,
    contact_only: Sequence[tuple[str, str]] = (),
) -> Robot3D:
    """A 3-D robot from a URDF file (and optionally its SRDF for disabled collision pairs).

    Args:
        urdf: the URDF path; ``package://`` meshes resolve against ``package_dirs`` and the
            URDF's parent folders.
        package_dirs: extra folders for ``package://`` paths.
        joints: the planning joints (revolute or continuous), in the URDF's order; None: every
            revolute and continuous joint.
        locked: values (rad or m) of other joints; unlisted ones lock at 0 clipped into their
            limits.
        srdf: an SRDF whose ``disable_collisions`` pairs are not checked for self-collision
            (see :func:`gdnplan.arm3d.pairs.self_collision_pairs`).
        name: the robot's name (default: the URDF's stem).
        contact_only: link pairs (link1, link2) checked for contact only: their signed
            distance must stay ≥ 0 whatever the clearance margin (pairs whose geometry keeps
            them within any useful margin but which can still collide;
            :mod:`gdnplan.arm3d.pairs`). Each must be a checked pair of two links with shapes
            (not same-body, adjacent or SRDF-disabled), else InputError.

    Raises:
        UnknownNameError: a missing URDF, mesh, SRDF, or an unknown joint name.
        InputError: a URDF that does not parse, invalid geometry (flat, NaN, huge), joints out
            of order, a locked value outside its limits.
    """
    path = urdf_path(urdf)
    dirs = check_folders(package_dirs)
    if joints is not None:
        joints = check_names(joints, "joints", "joint names")
    locked = check_locked(locked or {})
    if name is not None and (not isinstance(name, str) or not name.strip()):
        raise InputError(f"name: expected a robot name (a string) or None, got {name!r}")
    model, geom = load_urdf(
        RobotSpec(urdf=path, planning_joints=tuple(joints or ()), package_dirs=dirs)
    )
    movable = [
        model.names[j]
        for j in range(1, model.njoints)
        if model.joints[j].shortname().removeprefix("JointModel").startswith("R")
        and model.joints[j].nv == 1  # revolute (RX, RY, RZ, RevoluteUnaligned) or continuous
    ]
    planning = list(joints) if joints is not None else movable
    if joints is None and any(model.joints[model.getJointId(j)].nq == 2 for j in planning):
        model, geom = load_urdf(RobotSpec(path, tuple(planning), package_dirs=dirs))
    _check_joints(model, planning, movable, path.name)
    check_joint_limits(model, planning, path)
    check_mimic(path, planning)
    q_ref = _locked_configuration(model, planning, locked or {}, path.name)
    lock_mimics(model, q_ref, path, set(locked or {}))
    lock_ids = [j for j in range(1, model.njoints) if model.names[j] not in planning]
    reduced, reduced_geom = pin.buildReducedModel(model, geom, lock_ids, q_ref)
    shapes = [link_shape_from_geometry(reduced, obj) for obj in reduced_geom.geometryObjects]
    if not shapes:
        raise InputError(
            f"urdf: {path.name} has no collision geometry (<visual> elements are not read); "
            "add <collision> shapes"
        )
    pairs, disabled, contact = self_collision_pairs(model, reduced, shapes, srdf, contact_only)
    info = {"urdf": str(path)}
    return Robot3D(name or path.stem, reduced, shapes, pairs, disabled, info, contact)


def _check_joints(model: pin.Model, planning: list[str], movable: list[str], source: str) -> None:
    if not planning:
        raise InputError(f"joints: {source} has no revolute joint to plan; list planning joints")
    for jname in planning:
        if jname not in movable:
            if model.existJointName(jname):
                raise InputError(
                    f"joints: {jname!r} is not a revolute joint; lock it with a value instead"
                )
            raise UnknownNameError(
                f"joints: {jname!r} is not a joint of {source}; its revolute joints: {movable}"
            )
    order = [j for j in movable if j in planning]
    if len(set(planning)) != len(planning) or order != list(planning):
        raise InputError(f"joints: list each planning joint once, in the URDF's order: {order}")


def _locked_configuration(
    model: pin.Model, planning: list[str], locked: dict, source: str
) -> np.ndarray:
    """The full model's q with every non-planning joint at its locked value."""
    q = pin.neutral(model)
    for j in range(1, model.njoints):
        joint, jname = model.joints[j], model.names[j]
        if jname in planning or joint.nq != 1:
            continue
        lo, hi = model.lowerPositionLimit[joint.idx_q], model.upperPositionLimit[joint.idx_q]
        q[joint.idx_q] = float(np.clip(0.0, lo, hi))
    for jname, value in locked.items():
        if not isinstance(jname, str) or not model.existJointName(jname) or jname in planning:
            raise UnknownNameError(f"locked: {jname!r} is not a non-planning joint of {source}")
        set_locked(model, q, jname, value)
    return q
