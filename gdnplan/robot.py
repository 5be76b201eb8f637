"""Robots: a Pinocchio model reduced to its planning plane, one convex 2-D polygon per link part.

Every robot gdnplan plans for moves in a plane: all planning joints are revolute with axes along
the plane normal ``n``, so its points move by plane rotations (:class:`PlanarChain`,
:mod:`gdnplan.planar_chain`: batched positions and Jacobians in numpy); Pinocchio stays the
reference (``Robot.node_positions_pinocchio``) and a test proves the two equal. Joint angles
and seeds are checked by :mod:`gdnplan.robot_checks`, the plane and link polygons are
:mod:`gdnplan.robot_plane`'s (both re-exported here).
Robots are built from URDF files by :mod:`gdnplan.urdf_robot` (which checks that every
planning joint turns about ``n``); this module looks robots up by name in the registry
(:mod:`gdnplan.registry`), where :mod:`gdnplan.planar` and :mod:`gdnplan.ur5e` register the
shipped ones.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np
import pinocchio as pin

from .errors import InputError
from .limits import check_int, read_only
from .planar_chain import PlanarChain, cross_z, rot2
from .registry import ROBOTS, options_of
from .robot_checks import as_batch, check_joint_range, check_seed, first_outside, make_rng
from .robot_plane import LinkPolygon as LinkPolygon
from .robot_plane import Plane as Plane
from .robot_plane import apply_se3 as apply_se3
from .robot_plane import joint_axis

MAX_SAMPLES = 10**8  # configurations of one Robot.sample call


@dataclass(frozen=True, eq=False)
class Robot:
    """A planar-moving robot: Pinocchio model of its planning joints plus link polygons.

    Attributes:
        name: registry name (``"planar2"``, ``"planar7"``, ``"ur5e"``, ``"ur5"``) or, for a
            robot loaded from a user's URDF, a name that is none of these.
        model: Pinocchio model reduced to the planning joints (a serial chain).
        plane: the plane the robot moves in.
        polygons: convex link polygons (the robot graph's nodes are their vertices).
        lower: (dof,) lower joint limits (rad).
        upper: (dof,) upper joint limits (rad).
        base_radius: obstacles are never placed within this radius of joint 1 (m).
        info: free-form metadata (gripper state, stick size, source URDF).
    """

    name: str
    model: pin.Model
    plane: Plane
    polygons: tuple[LinkPolygon, ...]
    lower: np.ndarray
    upper: np.ndarray
    base_radius: float = 0.15
    info: dict = field(default_factory=dict)

    def __post_init__(self) -> None:
        lower, upper = check_joint_range(self.lower, self.upper, self.model.nq, "joint limits")
        object.__setattr__(self, "lower", read_only(lower))
        object.__setattr__(self, "upper", read_only(upper))

    # ---------------------------------------------------------------- structure
    @property
    def dof(self) -> int:
        return self.model.nq

    @property
    def joint_names(self) -> list[str]:
        return list(self.model.names)[1:]

    @property
    def n_links(self) -> int:
        """Number of link polygons (the per-link distance has this many columns)."""
        return len(self.polygons)

    @cached_property
    def chain(self) -> PlanarChain:
        data = self.model.createData()
        pin.forwardKinematics(self.model, data, np.zeros(self.dof))
        origins = np.array(
            [self.plane.project(data.oMi[j].translation) for j in range(1, self.dof + 1)]
        )
        signs = []
        for j in range(1, self.dof + 1):
            axis = data.oMi[j].rotation @ joint_axis(self.model, j)
            signs.append(float(np.sign(axis @ self.plane.normal)))
        return PlanarChain(origins.reshape(self.dof, 2), np.array(signs))

    @cached_property
    def node_polygon(self) -> np.ndarray:
        """(N,) index of the polygon each node (vertex) belongs to."""
        out = np.concatenate([np.full(len(p.vertices0), i) for i, p in enumerate(self.polygons)])
        out.setflags(write=False)  # the lever arms are cached from it (gdnplan.ccd)
        return out

    @cached_property
    def node_body(self) -> np.ndarray:
        """(N,) body index of each node."""
        out = np.array([self.polygons[i].body for i in self.node_polygon])
        out.setflags(write=False)
        return out

    @cached_property
    def nodes0(self) -> np.ndarray:
        """(N, 2) node positions at q = 0."""
        return read_only(np.concatenate([p.vertices0 for p in self.polygons]))

    @property
    def n_nodes(self) -> int:
        return len(self.nodes0)

    @cached_property
    def reach(self) -> float:
        """Upper bound on the distance of any robot point from joint 1 (m): the arm's reach.

        Chains the joint-to-joint distances: |p − o_1| ≤ Σ_{i<b} |o_{i+1} − o_i| + |p − o_b|.
        """
        o = self.chain.joint_origins
        hops = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(o, axis=0), axis=1))])
        body = np.maximum(self.node_body, 1) - 1
        return float(np.max(hops[body] + np.linalg.norm(self.nodes0 - o[body], axis=1)))

    # ---------------------------------------------------------------- sampling and checks
    def sample(
        self, n: int, seed: int | Sequence[int] | np.random.Generator | None = 0
    ) -> np.ndarray:
        """(n, dof) configurations uniform within the joint limits (rad).

        ``n`` is an integer in [0, MAX_SAMPLES]; ``seed`` is what :func:`check_seed` allows
        (None, an integer ≥ 0 or a list of them) or a ``numpy.random.Generator``, which is
        drawn from directly, so sampling continues the caller's stream (and advances it), as
        ``np.random.default_rng(generator)`` always did. Anything else is an InputError.
        """
        check_int(n, "n", 0, MAX_SAMPLES)
        return make_rng(seed).uniform(self.lower, self.upper, size=(n, self.dof))

    def check_q(self, q: np.ndarray, name: str = "q") -> np.ndarray:
        """Validate joint angles: returns a float64 (B, dof) array; raises InputError otherwise."""
        return as_batch(q, self.dof, name)

    def within_limits(self, q: np.ndarray, tol: float = 1e-9) -> np.ndarray:
        """(B,) True where every joint is within its limits."""
        q = self.check_q(q)
        return np.all((q >= self.lower - tol) & (q <= self.upper + tol), axis=1)

    # ---------------------------------------------------------------- kinematics
    def node_positions(self, q: np.ndarray) -> np.ndarray:
        """(B, N, 2) world positions of all polygon vertices at a batch q (B, dof)."""
        q = self.check_q(q)
        return self.chain.transform(self.nodes0, self.node_body, q)

    def node_jacobians(self, q: np.ndarray) -> np.ndarray:
        """(B, N, 2, dof) Jacobians of the node positions with respect to q."""
        q = self.check_q(q)
        points = self.chain.transform(self.nodes0, self.node_body, q)
        return self.chain.jacobian(points, self.node_body, q)

    def link_polygons(self, q: np.ndarray) -> list[np.ndarray]:
        """World polygons (m_k, 2) of one configuration q (dof,)."""
        if np.ndim(q) != 1:
            raise InputError(f"q: expected one configuration of shape ({self.dof},), got {q!r}")
        nodes = self.node_positions(q)[0]
        return [nodes[self.node_polygon == i] for i in range(self.n_links)]

    def body_poses(self, q: np.ndarray) -> np.ndarray:
        """(B, dof + 1, 3) planar poses (x, y, θ) of every body; body 0 is the fixed base.

        The pose maps q = 0 plane coordinates of a body point p⁰ to p = R(θ)p⁰ + (x, y). Body b
        hangs from joint b − 1 at o_{b−1} (q = 0 coordinates), so composing one joint more,

            θ_b = θ_{b−1} + s_{b−1} q_{b−1},    t_b = t_{b−1} + R(θ_{b−1}) o_{b−1} − R(θ_b) o_{b−1},

        with θ_0 = 0, t_0 = 0: two cumulative sums over the chain, no loop over joints.
        """
        q = self.check_q(q)
        theta = np.concatenate([np.zeros((len(q), 1)), np.cumsum(q * self.chain.joint_signs, 1)], 1)
        c, s = np.cos(theta)[..., None], np.sin(theta)[..., None]  # (B, dof + 1, 1)
        ox, oy = self.chain.joint_origins[:, :1], self.chain.joint_origins[:, 1:]  # (dof, 1)

        def rotated(k: slice) -> np.ndarray:  # R(θ_k) o (B, dof, 2) for θ_k = θ[:, k]
            return np.concatenate([c[:, k] * ox - s[:, k] * oy, s[:, k] * ox + c[:, k] * oy], -1)

        steps = rotated(slice(0, -1)) - rotated(slice(1, None))
        origin = np.concatenate([np.zeros((len(q), 1, 2)), np.cumsum(steps, 1)], 1)
        return np.concatenate([origin, theta[..., None]], -1)

    def node_positions_pinocchio(self, q: np.ndarray) -> np.ndarray:
        """Reference node positions (B, N, 2) from Pinocchio frame placements."""
        q = self.check_q(q)
        data = self.model.createData()
        out = np.empty((len(q), self.n_nodes, 2))
        for b, qb in enumerate(q):
            pin.framesForwardKinematics(self.model, data, qb)
            rows = [apply_se3(data.oMf[p.frame], p.vertices_frame) for p in self.polygons]
            out[b] = self.plane.project(np.concatenate(rows))
        return out

    def node_jacobians_pinocchio(self, q: np.ndarray) -> np.ndarray:
        """Reference node Jacobians (B, N, 2, dof) from Pinocchio frame Jacobians.

        For a point p on frame f: ṗ = v_f + ω_f × (p − o_f) with (v_f, ω_f) the frame's
        LOCAL_WORLD_ALIGNED twist, projected on the plane axes.
        """
        q = self.check_q(q)
        data = self.model.createData()
        out = np.empty((len(q), self.n_nodes, 2, self.dof))
        frame_ref = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
        for b, qb in enumerate(q):
            pin.computeJointJacobians(self.model, data, qb)
            pin.updateFramePlacements(self.model, data)
            n = 0
            for p in self.polygons:
                jac = pin.getFrameJacobian(self.model, data, p.frame, frame_ref)
                o = data.oMf[p.frame].translation
                for x in apply_se3(data.oMf[p.frame], p.vertices_frame):
                    lin = jac[:3] - np.cross(x - o, jac[3:].T).T  # v + ω × r = v − r × ω
                    out[b, n] = self.plane.axes @ lin
                    n += 1
        return out


# -------------------------------------------------------------------- registry
def register_robot(name: str) -> Callable:
    """Decorator registering a robot factory under ``name`` for :func:`load_robot`."""
    return ROBOTS.register(name)


def robot_names() -> list[str]:
    return ROBOTS.names()


def robot_options(name: str) -> set[str]:
    """The options :func:`load_robot` takes for the registered robot ``name`` (its factory's
    keyword parameters, e.g. ``gripper`` for ur5e): the ``[robot]`` keys beyond ``name``."""
    return factory_options(ROBOTS.get(name))


factory_options = options_of  # names of a factory's keyword parameters (registry.options_of)


def load_robot(name: str, **options) -> Robot:
    """Build a registered robot (``planar2``, ``planar7``, ``ur5e``, ``ur5``) by name.

    Options are passed to the factory (e.g. ``gripper="holding", stick_length=0.3`` for ur5e).
    Results without options are cached: the same name returns the same object.
    """
    if options:  # an option the factory does not take: InputError (registry.build)
        return ROBOTS.build(name, **options)
    factory = ROBOTS.get(name)  # first: a name that is no string is an UnknownNameError
    if name not in _CACHE:
        _CACHE[name] = factory()
    return _CACHE[name]


_CACHE: dict[str, Robot] = {}


__all__ = [  # re-exported too: planar_chain (PlanarChain, cross_z, rot2), robot_checks
    "MAX_SAMPLES",
    "LinkPolygon",
    "PlanarChain",
    "Plane",
    "Robot",
    "apply_se3",
    "as_batch",
    "check_seed",
    "cross_z",
    "factory_options",
    "first_outside",
    "load_robot",
    "make_rng",
    "register_robot",
    "robot_names",
    "robot_options",
    "rot2",
]
