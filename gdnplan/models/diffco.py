"""DiffCo (Zhi, Das, Yip, "DiffCo: Auto-Differentiable Proxy Collision Detection with Multi-class
Labels for Safety-Aware Trajectory Optimization", T-RO 2022), written from the paper's description.

A kernel perceptron over configurations with the forward-kinematics kernel. Control points are
the robot's graph nodes x(q) = robot.node_positions(q) ∈ R^{N×2}; the kernel is the rational
quadratic kernel on them,

    k(q, q') = (1 + γ/p · r²)^(−p),   r² = (1/N) Σ_n ‖x_n(q) − x_n(q')‖²   (m², p = 2),

(r² averages over the N points so that γ (m⁻²) does not depend on the robot). The collision
score is s(q) = Σ_i α_i k(q, q_i) over support points q_i; s > 0 predicts a collision. Its
gradient uses the node Jacobians J_n(q) = ∂x_n/∂q (B, N, 2, dof):

    ∂s/∂q = Σ_i α_i ∂k/∂r² · (2/N) Σ_n (x_n(q) − x_n(q_i))ᵀ J_n(q),
    ∂k/∂r² = −γ (1 + γ/p · r²)^(−p−1).

Training is Fastron's perceptron (Das & Yip 2020): labels y = +1 (coal f ≤ margin) or −1,
hypothesis F = K α; repeatedly correct the worst misclassified point i by
Δα_i = β^{(1+y_i)/2} y_i − F_i (K_ii = 1), and drop support points whose removal keeps
y_j (F_j − α_j) > 0, until every training point is classified correctly or the iteration budget
ends. Active learning for a changed environment (DiffCo §IV-D / Fastron): relabel the support
points with coal in the new scene, add Gaussian perturbations around them (exploitation) and
uniform samples (exploration), label those with coal and continue the perceptron from the old
weights. The fitted variant (DiffCo's smooth surrogate for optimisation) is kernel ridge
regression of coal's signed distance over the labelled pool P (the training or active-learning
configurations, at most ``FIT_MAX`` of them) with the same kernel: w = (K_PP + λI)⁻¹ f_P,
f̃(q) = Σ_{j∈P} w_j k(q, q_j). Fitting only the support points, which all lie on the collision
boundary, leaves f̃ ≈ 0 away from it and its gradient pointing the wrong way.

As a :class:`~gdnplan.models.DistanceModel` DiffCo returns −s (larger = freer), so AUC and ACD
are defined but it is not a distance in metres (``is_distance = False``; MAE is N/A). DiffCo is
tied to the environment it was trained in: ``distance`` ignores the scene's obstacles.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ..distance import signed_distance
from ..errors import InputError
from ..limits import check_int
from ..robot import Robot, make_rng
from ..scene import Scene, check_scene
from .fields import check_real

CHUNK = 1024  # query rows per kernel block
FIT_MAX = 3000  # labelled configurations in the fitted surrogate
MAX_POOL = 10_000  # labelled configurations of one perceptron fit: an n² kernel (800 MB)
MAX_FASTRON_ITER = 10**8  # perceptron updates of one fit


def check_training(gamma: object, beta: object, margin: object, max_iter: object) -> None:
    """InputError naming the first setting out of its range: ``gamma`` in [1e-6, 1e6] m⁻²,
    ``beta`` in [1e-6, 1e6], ``margin`` in [−10, 10] m, ``max_iter`` in 1 … 10⁸."""
    check_real("gamma", gamma, 1e-6, 1e6, " m⁻²")
    check_real("beta", beta, 1e-6, 1e6)
    check_real("margin", margin, -10.0, 10.0, " m")
    check_int(max_iter, "max_iter", 1, MAX_FASTRON_ITER)


def same_kinematics(a: Robot, b: Robot) -> bool:
    """True when robots ``a`` and ``b`` have one name, joint count, limits and node positions
    (DiffCo's control points) at their lower, upper and middle configurations."""
    if a is b:
        return True
    if (a.name, a.dof, a.n_nodes) != (b.name, b.dof, b.n_nodes):
        return False
    if not (np.array_equal(a.lower, b.lower) and np.array_equal(a.upper, b.upper)):
        return False
    probe = np.stack([a.lower, a.upper, (a.lower + a.upper) / 2])
    return bool(np.array_equal(a.node_positions(probe), b.node_positions(probe)))


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


@dataclass(frozen=True, eq=False)
class DiffCo:
    """A trained DiffCo collision score (see the module docstring).

    Attributes:
        kernel: the FK kernel.
        support: (S, dof) support configurations q_i.
        alpha: (S,) perceptron weights α_i.
        pool: (P, dof) labelled configurations of the last training or update.
        pool_d: (P,) coal signed distance at ``pool`` (m), in the training scene.
        centers: (C, dof) configurations of the returned value: the support points for the
            score, the (at most ``FIT_MAX``) pool configurations for the fitted surrogate.
        fit_weights: (C,) weights w of the fitted surrogate, or None for the perceptron score.
        beta, margin, ridge: training settings (collision weight, label margin (m), λ of the fit).
        name: display name.
    """

    kernel: FKKernel
    support: np.ndarray
    alpha: np.ndarray
    pool: np.ndarray
    pool_d: np.ndarray
    fit_weights: np.ndarray | None = None
    beta: float = 1.0
    margin: float = 0.0
    ridge: float = 1e-3
    name: str = "DiffCo"
    is_distance = False

    @classmethod
    def train(
        cls,
        scene: Scene,
        n: int = 3000,
        seed: int = 0,
        gamma: float = 10.0,
        beta: float = 1.0,
        margin: float = 0.0,
        max_iter: int = 20_000,
    ) -> DiffCo:
        """Train on n uniform configurations of ``scene`` labelled by coal (``n`` in 1 …
        :data:`MAX_POOL`; the other settings: :func:`check_training`)."""
        check_scene(scene, "planar")
        check_int(n, "n", 1, MAX_POOL, "the kernel matrix is n² numbers")
        check_training(gamma, beta, margin, max_iter)
        kernel = FKKernel(scene.robot, float(gamma))
        q = scene.robot.sample(n, seed=seed)
        d = signed_distance(scene, q)
        model = cls(kernel, q[:0], np.zeros(0), q, d, beta=beta, margin=margin)
        return model._fit(q, d, np.zeros(n), max_iter)

    def _fit(self, q: np.ndarray, d: np.ndarray, alpha0: np.ndarray, max_iter: int) -> DiffCo:
        """Run Fastron on (q, labels from d) from weights alpha0; keep the support points."""
        feats = self.kernel.features(q)
        y = np.where(d <= self.margin, 1.0, -1.0)
        alpha = fastron(self.kernel.matrix(feats, feats), y, alpha0, self.beta, max_iter)
        keep = alpha != 0
        return replace(self, support=q[keep], alpha=alpha[keep], pool=q, pool_d=d, fit_weights=None)

    def adapt(
        self,
        scene: Scene,
        n_exploit: int = 2,
        n_explore: int = 500,
        sigma: float = 0.1,
        seed: int | np.random.Generator | None = 0,
        max_iter: int = 20_000,
    ) -> DiffCo:
        """Active-learning update to a changed environment (labels from coal in ``scene``).

        Args:
            scene: the new environment (same robot).
            n_exploit: Gaussian perturbations (σ = ``sigma`` rad per joint) per support point.
            n_explore: uniform random configurations.
            seed: sampling seed: None, an integer ≥ 0, a list of them or a
                ``numpy.random.Generator`` (its stream continues), else InputError.
            max_iter: perceptron update budget.

        Returns:
            A new DiffCo (perceptron score; call :meth:`fitted` for the surrogate).
        """
        robot = self.kernel.robot
        self.check_robot(scene)
        pool = len(self.support) * (1 + check_int(n_exploit, "n_exploit", 0, MAX_POOL))
        check_int(n_explore, "n_explore", 0, MAX_POOL - pool, f"at most {MAX_POOL} in all")
        sigma = check_real("sigma", sigma, 0.0, 10.0, " rad")
        check_int(max_iter, "max_iter", 1, MAX_FASTRON_ITER)
        rng = make_rng(seed)
        near = np.repeat(self.support, n_exploit, 0)
        near = np.clip(near + rng.normal(0, sigma, near.shape), robot.lower, robot.upper)
        q = np.concatenate([self.support, near, robot.sample(n_explore, seed=rng)])
        d = signed_distance(scene, q)
        alpha0 = np.r_[self.alpha, np.zeros(len(q) - len(self.support))]
        return self._fit(q, d, alpha0, max_iter)

    def fitted(self) -> DiffCo:
        """The smooth surrogate: kernel ridge regression of coal's f over the labelled pool
        (``ridge`` λ in [0, 1e6])."""
        check_real("ridge", self.ridge, 0.0, 1e6)
        feats = self.kernel.features(self.pool[:FIT_MAX])
        K = self.kernel.matrix(feats, feats) + self.ridge * np.eye(len(feats))
        w = np.linalg.solve(K, self.pool_d[:FIT_MAX])
        return replace(self, fit_weights=w, name=f"{self.name} (fitted)")

    @property
    def centers(self) -> np.ndarray:
        """(C, dof) kernel centres of the returned value (support points or the fit pool)."""
        return self.support if self.fit_weights is None else self.pool[: len(self.fit_weights)]

    # ------------------------------------------------------------------ DistanceModel
    @property
    def weights(self) -> np.ndarray:
        """(S,) the weights of the returned value: −α (score) or w (fitted surrogate)."""
        return -self.alpha if self.fit_weights is None else self.fit_weights

    def check_robot(self, scene: Scene) -> None:
        """InputError unless ``scene`` is planar and its robot is the one DiffCo was trained
        for (:func:`same_kinematics`): its control points are that robot's nodes."""
        check_scene(scene, "planar")
        mine, have = self.kernel.robot, scene.robot
        if not same_kinematics(mine, have):
            raise InputError(
                f"scene: this DiffCo was trained for the {mine.name} robot ({mine.dof} joints) "
                f"and the scene's robot is {have.name} ({have.dof} joints) with other "
                "kinematics; train DiffCo in a scene of this robot (DiffCo.train)"
            )

    def distance(self, scene: Scene, q: np.ndarray) -> np.ndarray:
        """(B,) −s(q) (or the fitted surrogate); ``scene`` only checks the robot and q
        (obstacles unused)."""
        self.check_robot(scene)
        q = scene.robot.check_q(q)
        feats = self.kernel.features(q)
        sf = self.kernel.features(self.centers)
        out = np.empty(len(q))
        for s in range(0, len(q), CHUNK):
            out[s : s + CHUNK] = self.kernel.matrix(feats[s : s + CHUNK], sf) @ self.weights
        return out

    def predict_dataset(self, ds, grad: bool) -> tuple[np.ndarray, np.ndarray | None]:
        """A dataset's samples in one pass (DiffCo ignores their obstacles, see above)."""
        scene = Scene(self.kernel.robot, ())
        if grad:
            return self.distance_and_grad(scene, ds.q)
        return self.distance(scene, ds.q), None

    def distance_and_grad(self, scene: Scene, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """((B,), (B, dof)) the value and its exact gradient through the node Jacobians."""
        self.check_robot(scene)
        q = scene.robot.check_q(q)
        n_nodes = self.kernel.robot.n_nodes
        feats = self.kernel.features(q)  # (B, 2N) = x / √N
        jac = self.kernel.robot.node_jacobians(q).reshape(len(q), 2 * n_nodes, q.shape[1])
        sf = self.kernel.features(self.centers)
        value, grad = np.empty(len(q)), np.empty(q.shape)
        for s in range(0, len(q), CHUNK):
            a = feats[s : s + CHUNK]
            k, dk = self.kernel.from_features(a, sf)
            value[s : s + CHUNK] = k @ self.weights
            c = dk * self.weights  # (b, S): α_i ∂k/∂r²
            # ∂r²/∂x = 2 (x/√N − x_i/√N) / √N  →  ∂/∂(scaled feature) times 1/√N
            dfeat = 2 * (a * c.sum(1, keepdims=True) - c @ sf) / np.sqrt(n_nodes)
            grad[s : s + CHUNK] = np.einsum("bf,bfj->bj", dfeat, jac[s : s + CHUNK])
        return value, grad
