"""DiffCo's forward-kinematics kernel, its weighted sums with their gradient, and Fastron's
perceptron updates (the model's mathematics, :mod:`gdnplan.models.diffco`).

Control points are the robot's graph nodes x(q) = robot.node_positions(q) ∈ R^{N×2}; the
kernel is the rational quadratic kernel on them,

    k(q, q') = (1 + γ/p · r²)^(−p),   r² = (1/N) Σ_n ‖x_n(q) − x_n(q')‖²   (m², p = 2),

(r² averages over the N points so that γ (m⁻²) does not depend on the robot), with
∂k/∂r² = −γ (1 + γ/p · r²)^(−p−1). Fastron (Das & Yip 2020) fits weights α to labels y = ±1
(+1 = collision) through F = K α: repeatedly correct the worst misclassified point i by
Δα_i = β^{(1+y_i)/2} y_i − F_i (K_ii = 1), and drop support points whose removal keeps
y_j (F_j − α_j) > 0, until every training point is classified correctly or the budget ends.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..robot import Robot

CHUNK = 1024  # query rows per kernel block


@dataclass(frozen=True)
class FKKernel:
    """Rational-quadratic kernel on forward-kinematics control points (see module docstring).

    Attributes:
        robot: the robot whose node positions are the control points.
        gamma: inverse squared length scale γ (m⁻²).
        p: rational-quadratic exponent.
    """

    robot: Robot
    gamma: float = 10.0
    p: float = 2.0

    def features(self, q: np.ndarray) -> np.ndarray:
        """(B, 2N) control points of q (B, dof), flattened and scaled by 1/√N (m)."""
        x = self.robot.node_positions(q)
        return x.reshape(len(x), 2 * x.shape[1]) / np.sqrt(x.shape[1])  # (0, 2N) when B = 0

    def from_features(self, a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Kernel (A, B) and ∂k/∂r² (A, B) between feature rows a (A, 2N) and b (B, 2N)."""
        r2 = np.maximum((a * a).sum(1)[:, None] + (b * b).sum(1)[None] - 2 * a @ b.T, 0.0)
        base = 1.0 + self.gamma / self.p * r2
        return base ** (-self.p), -self.gamma * base ** (-self.p - 1)

    def matrix(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        """(A, B) kernel values between feature rows."""
        return self.from_features(a, b)[0]


def fastron(
    K: np.ndarray,
    y: np.ndarray,
    alpha: np.ndarray,
    beta: float = 1.0,
    max_iter: int = 20_000,
) -> np.ndarray:
    """Fastron perceptron updates from initial weights.

    Args:
        K: (n, n) kernel matrix of the training points (unit diagonal).
        y: (n,) labels ±1 (+1 = collision).
        alpha: (n,) initial weights (zeros for a fresh model).
        beta: weight of collision corrections (β > 1 favours conservative predictions).
        max_iter: update budget.

    Returns:
        (n,) weights α with sign(K α) = y on the training points when converged.
    """
    alpha = alpha.astype(float).copy()
    F = K @ alpha
    for _ in range(max_iter):
        margin = y * F
        i = int(np.argmin(margin))
        if margin[i] <= 0:
            delta = beta ** ((1 + y[i]) / 2) * y[i] - F[i]
            alpha[i] += delta
            F += delta * K[:, i]
            continue
        active = alpha != 0
        removable = np.where(active, y * (F - alpha), -np.inf)
        j = int(np.argmax(removable))
        if removable[j] > 0 and active.sum() > 1:
            F -= alpha[j] * K[:, j]
            alpha[j] = 0.0
            continue
        break
    return alpha


def kernel_sum(
    kernel: FKKernel, centers: np.ndarray, weights: np.ndarray, q: np.ndarray
) -> np.ndarray:
    """(B,) Σ_i w_i k(q, c_i) at checked configurations q (B, dof) (rad) over the kernel
    centres c (C, dof) with weights w (C,), ``CHUNK`` query rows at a time."""
    feats = kernel.features(q)
    sf = kernel.features(centers)
    out = np.empty(len(q))
    for s in range(0, len(q), CHUNK):
        out[s : s + CHUNK] = kernel.matrix(feats[s : s + CHUNK], sf) @ weights
    return out


def kernel_sum_and_grad(
    kernel: FKKernel, centers: np.ndarray, weights: np.ndarray, q: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """((B,), (B, dof)) :func:`kernel_sum` and its exact gradient in q through the node
    Jacobians J_n(q) (B, N, 2, dof):

        ∂/∂q = Σ_i w_i ∂k/∂r² · (2/N) Σ_n (x_n(q) − x_n(c_i))ᵀ J_n(q).
    """
    n_nodes = kernel.robot.n_nodes
    feats = kernel.features(q)  # (B, 2N) = x / √N
    jac = kernel.robot.node_jacobians(q).reshape(len(q), 2 * n_nodes, q.shape[1])
    sf = kernel.features(centers)
    value, grad = np.empty(len(q)), np.empty(q.shape)
    for s in range(0, len(q), CHUNK):
        a = feats[s : s + CHUNK]
        k, dk = kernel.from_features(a, sf)
        value[s : s + CHUNK] = k @ weights
        c = dk * weights  # (b, S): α_i ∂k/∂r²
        # ∂r²/∂x = 2 (x/√N − x_i/√N) / √N  →  ∂/∂(scaled feature) times 1/√N
        dfeat = 2 * (a * c.sum(1, keepdims=True) - c @ sf) / np.sqrt(n_nodes)
        grad[s : s + CHUNK] = np.einsum("bf,bfj->bj", dfeat, jac[s : s + CHUNK])
    return value, grad


__all__ = ["CHUNK", "FKKernel", "fastron", "kernel_sum", "kernel_sum_and_grad"]
