r"""Continuous collision certificate of 3-D joint paths (conservative advancement).

Along the straight joint-space piece q(s) = q_a + s (q_b − q_a), s ∈ [0, 1], a point p of robot
shape σ (on body b) moves with ṗ = Σ_j ω_j × (p − o_j) Δq_j over the planning joints j that
support b, where ω_j is joint j's unit axis through its origin o_j. Its speed is bounded by
the lever arms r_{σ,j} ≥ |p − o_j|, rigid bounds valid at every configuration:

    r_{σ,j} = Σ_{i ∈ path(j → b), i ≠ j} |t_i| + |c_σ| + ρ_σ                       (m)

with t_i the fixed translation of joint i in its parent's frame (the distance between
consecutive joint origins), c_σ the shape's bounding-sphere centre in body b's joint frame and
ρ_σ its radius; r_{σ,j} = 0 for joints that do not move shape σ. A prismatic joint j moves
every point below it by a_j Δq_j, |a_j| = 1: r_{σ,j} = 1; one below a revolute joint would
change |t_i| with its coordinate, and such robots (like any joint kind but these two) are
refused (:func:`joint_kind`). So no point of σ travels farther
than δ_σ = Σ_j r_{σ,j} |Δq_j| along the piece. A self pair's distance depends only on the
relative pose of its two shapes, which joints supporting both do not change (they move both
rigidly), so it changes by at most

    δ_στ = Σ_{j ∈ S_σ \ S_τ} r_{σ,j} |Δq_j| + Σ_{j ∈ S_τ \ S_σ} r_{τ,j} |Δq_j|   ≤ δ_σ + δ_τ,

S_σ the joints supporting σ's body (on a chain one shape's joints contain the other's, and
δ_στ ≤ max(δ_σ, δ_τ)). The distance of any pair changes by at most
Δ = max(max_σ δ_σ, max_{(σ,τ) self pairs} δ_στ). As in :mod:`gdnplan.ccd`, with proven
lower bounds d̲_a, d̲_b at the ends (coal's estimate minus ``COAL_SLACK`` (1 + |d| + ρ̄), ρ̄ the
largest swept-sphere radius sum of a pair, :attr:`~gdnplan.arm3d.narrow3d.PairTable.swept_max`:
coal's tolerance is relative to the distance of the pair's cores, a capsule's segment),

    d(q(s)) ≥ L = (d̲_a + d̲_b − Δ) / 2      for every s ∈ [0, 1],                    (1)

and :func:`certify_path3d` bisects pieces until (1) exceeds the margin on every piece, or
fails: a checked configuration within the margin, a piece too small to bisect, or the check
budget spent — never an acceptance without a proof. Self-collision is included.

Contact-only self pairs (:mod:`gdnplan.arm3d.pairs`) are proven out of contact, not clear of
the margin M: the certificate runs on c(q) = min_k (d_k + o_k) with the offset o_k = M on
contact-only pairs and 0 on every other pair (:mod:`gdnplan.arm3d.narrow3d`), and

    c(q) > M   ⟺   d_k > M for every obstacle and ordinary self pair, d_k > 0 for every
                   contact-only pair.

o_k is constant, so c changes along a piece by at most Δ as every d_k does and (1) holds for c
unchanged. coal's allowance stays valid: a checked c > M ≥ 0 has d_k > 0 on contact-only pairs,
so |d_k + o_k| ≥ |d_k| and COAL_SLACK (1 + |c| + ρ̄) covers them. The reported ``lower_bound`` is a
proven lower bound on c: on the obstacle and ordinary self clearance, and with
``lower_bound − margin`` (> 0 when ``ok``) on the contact-only pairs' distances;
``min_distance`` is the smallest checked c. :class:`Certificate3D` names the contact-only
pairs proven.
"""

from __future__ import annotations

import math
import weakref
from dataclasses import dataclass

import numpy as np

from ..ccd import Certificate, certify_by_bisection, check_certify_args
from ..errors import InputError
from ..robot_checks import check_pairs
from ..scene import check_scene
from .distance3d import checker3d
from .robot3d import Robot3D
from .scene3d import Scene3D, check_robot3d


@dataclass(frozen=True)
class Certificate3D(Certificate):
    """A :class:`gdnplan.ccd.Certificate` of a 3-D path (module docstring).

    When ``ok``: every obstacle and ordinary self pair keeps d > ``margin`` (≥ ``lower_bound``)
    and every pair of ``contact_only`` keeps d > 0 (≥ ``lower_bound − margin``) on the whole
    continuous path. ``lower_bound`` and ``min_distance`` bound c(q) = min_k (d_k + o_k).

    Attributes:
        margin: the clearance proven for obstacle and ordinary self pairs (m).
        contact_only: the contact-only link pairs ("link1–link2", sorted) proven out of
            contact, with no margin.
    """

    margin: float = 0.0
    contact_only: tuple[str, ...] = ()


_ARMS: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()  # robot -> its lever arms


def lever_arms3d(robot: Robot3D) -> np.ndarray:
    """(S, dof) bounds r_{σ,j} ≥ |∂p/∂q_j| for every point p of shape σ, any q: |p − o_j| (m)
    for a revolute joint, 1 for a prismatic one (:func:`_lever_arms3d`); computed once per
    robot (the certificate asks for them on every bisection round). InputError for a joint
    kind without a proven bound (:func:`joint_kind`)."""
    check_robot3d(robot)
    if robot not in _ARMS:
        arms = _lever_arms3d(robot)
        arms.setflags(write=False)
        _ARMS[robot] = arms
    return _ARMS[robot]


_REVOLUTE = ("RX", "RY", "RZ", "RevoluteUnaligned")  # Pinocchio kinds turning about an axis
_PRISMATIC = ("PX", "PY", "PZ", "PrismaticUnaligned")  # ... sliding along one


def joint_kind(model, j: int) -> str:
    """The kind of joint j: "R" revolute (one coordinate, rad), "P" prismatic (m); InputError
    for any other kind (continuous joints with two coordinates, helical, mimic, free-flyer):
    the certificate's motion bound is proven for these two only."""
    joint = model.joints[j]
    kind = joint.shortname().removeprefix("JointModel")
    if joint.nq == joint.nv == 1 and kind in _REVOLUTE:
        return "R"
    if joint.nq == joint.nv == 1 and kind in _PRISMATIC:
        return "P"
    raise InputError(
        f"robot: joint {model.names[j]!r} is a {kind} joint; the continuous certificate bounds "
        "the motion of revolute and prismatic joints only"
    )


def _lever_arms3d(robot: Robot3D) -> np.ndarray:
    """The arms of :func:`lever_arms3d`: a revolute joint j moves a point p at |p − o_j| per
    rad, bounded by chaining the fixed joint-to-joint translations |t_i| below j; a prismatic
    joint moves every point below it by exactly its own travel (1 m per m). A prismatic joint
    below a revolute one changes that chain's length with its coordinate (no rigid bound):
    InputError."""
    model = robot.model
    hop = np.array(
        [np.linalg.norm(model.jointPlacements[i].translation) for i in range(model.njoints)]
    )
    kinds = {j: joint_kind(model, j) for j in range(1, model.njoints)}
    arms = np.zeros((len(robot.shapes), robot.dof))
    for k, s in enumerate(robot.shapes):
        reach = np.linalg.norm(s.placement[:3, :3] @ s.center + s.placement[:3, 3]) + s.radius
        chain = list(model.supports[s.body])[1:]  # joints from the base to b (universe dropped)
        for pos, j in enumerate(chain):
            below = chain[pos + 1 :]  # joints strictly between j and b, and b itself
            if kinds[j] == "P":
                arms[k, model.joints[j].idx_v] = 1.0
                continue
            sliding = [model.names[i] for i in below if kinds[i] == "P"]
            if sliding:
                raise InputError(
                    f"robot: prismatic joint {sliding[0]!r} lies below revolute joint "
                    f"{model.names[j]!r}: the lever arm grows with its travel and the "
                    "continuous certificate has no rigid bound for it"
                )
            arms[k, model.joints[j].idx_v] = reach + hop[below].sum()
    return arms


_PAIR_ARMS: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()  # robot -> (P, dof)


def self_pair_arms(robot: Robot3D) -> np.ndarray:
    """(P, dof) weights w_p with δ_στ = w_p · |Δq| for every self pair p = (σ, τ): r_{σ,j}
    on the joints moving σ but not τ, r_{τ,j} on those moving τ but not σ, 0 on the rest (m)."""
    if robot not in _PAIR_ARMS:
        arms, model = lever_arms3d(robot), robot.model
        moves = np.zeros((len(robot.shapes), robot.dof), bool)
        for k, shape in enumerate(robot.shapes):
            for j in list(model.supports[shape.body])[1:]:
                moves[k, model.joints[j].idx_v] = True
        a, b = robot.self_pairs[:, 0], robot.self_pairs[:, 1]
        weights = arms[a] * (moves[a] & ~moves[b]) + arms[b] * (moves[b] & ~moves[a])
        weights.setflags(write=False)
        _PAIR_ARMS[robot] = weights.reshape(-1, robot.dof)
    return _PAIR_ARMS[robot]


def motion_bound3d(robot: Robot3D, qa: np.ndarray, qb: np.ndarray) -> np.ndarray:
    """(B,) bound Δ on the change of any pair's distance from qa to qb (B, dof) (m); one
    configuration on either side pairs with every row of the other."""
    step = np.abs(check_pairs(check_robot3d(robot), qa, qb))
    out = (step @ lever_arms3d(robot).T).max(axis=1)  # obstacle pairs: max_σ δ_σ
    if len(robot.self_pairs):
        out = np.maximum(out, (step @ self_pair_arms(robot).T).max(axis=1))
    return out


def certify_path3d(
    scene: Scene3D,
    q_path: np.ndarray,
    margin: float = 0.0,
    min_splits: int = 4,
    max_checks: int = 20_000,
    tol: float = math.inf,
    stop_early: bool = False,
) -> Certificate:
    """Prove that the piecewise-linear joint path q_path (K, dof) keeps the exact signed
    distance of obstacle and ordinary self pairs above ``margin`` (m) and of contact-only self
    pairs above 0 on the whole continuous path (module docstring).

    ``tol`` (m): also bisect until the reported lower bound is within ``tol`` of the smallest
    checked distance (inf: prove the margin only); ``stop_early``: return at the first
    configuration within the margin. Returns a :class:`gdnplan.ccd.Certificate`; ``ok`` only
    with a proof on every piece (then ``reason`` is ""). ``min_splits`` ≤ ``MAX_SPLITS``; the
    budget ``max_checks`` is never exceeded: initial pieces needing more fail before any coal
    call (``ok=False``, ``n_checks=0``, the reason; :mod:`gdnplan.ccd`). Returns a
    :class:`Certificate3D`.
    """
    check_scene(scene, "3d", "gdnplan.certify_path")
    check_certify_args(margin, tol, min_splits, max_checks, stop_early)
    robot = scene.robot
    q_path = robot.check_q(q_path, "q_path")
    if len(q_path) < 2:
        raise InputError("q_path: a path needs at least 2 waypoints")
    checker = checker3d(scene)
    cert = certify_by_bisection(
        q_path,
        lambda q: checker.evaluate(q, contact_offset=margin).distance,
        lambda qa, qb: motion_bound3d(robot, qa, qb),
        margin,
        tol,
        min_splits,
        stop_early,
        max_checks,
        checker.swept_max,
    )
    pairs = tuple(sorted("–".join(sorted(p)) for p in robot.contact_only))
    return Certificate3D(**vars(cert), margin=float(margin), contact_only=pairs)
