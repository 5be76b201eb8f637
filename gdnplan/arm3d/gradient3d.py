"""The exact gradient of a 3-D pair's signed distance with respect to the joints.

For pair k between shape 1 (a robot shape) and shape 2 (an obstacle or a robot shape) with
witness points p₁, p₂ and unit normal n from shape 1 to shape 2 (p₂ − p₁ = d_k n,
:mod:`gdnplan.arm3d.narrow3d`), moving both shapes rigidly changes d_k to first order by the
normal component of the witness points' relative velocity, so

    ∂d_k/∂q = nᵀ (J(p₂) − J(p₁))                                     (1, dof), m/rad

with J(p) (3, dof) the Jacobian of the world point p fixed on its body
(:func:`~gdnplan.arm3d.robot3d.point_jacobians`, LOCAL_WORLD_ALIGNED; zero for an obstacle):
for an obstacle pair ∂d/∂q = −nᵀ J(p₁). The gradient is exact wherever the minimising pair and
its witness points are unique (away from ties and switches).
"""

from __future__ import annotations

import numpy as np

from .narrow3d import PairTable
from .robot3d import point_jacobians


def pair_gradients(table: PairTable, q: np.ndarray, pair: np.ndarray, p1, p2, normal) -> np.ndarray:
    """(T, dof) gradients (1) of pairs ``pair`` (T,) at one configuration q (dof,) (rad), with
    their witness points p₁, p₂ (T, 3) and normals (T, 3) (m); zero rows where pair = −1."""
    robot = table.robot
    out = np.zeros((len(pair), robot.dof))
    live = pair >= 0
    if not live.any():
        return out
    jac, origins = robot.joint_jacobians(q)
    k = pair[live]
    body_a = robot.shape_body[table.pair_a[k]]
    ja = point_jacobians(jac[body_a], origins[body_a], p1[live])
    grad = -np.einsum("ti,tij->tj", normal[live], ja)
    self_rows = table.is_self[k]
    if self_rows.any():
        body_b = robot.shape_body[table.pair_b[k[self_rows]]]
        jb = point_jacobians(jac[body_b], origins[body_b], p2[live][self_rows])
        grad[self_rows] += np.einsum("ti,tij->tj", normal[live][self_rows], jb)
    out[live] = grad
    return out


__all__ = ["pair_gradients"]
