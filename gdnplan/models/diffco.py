"""DiffCo (Zhi, Das, Yip, "DiffCo: Auto-Differentiable Proxy Collision Detection with Multi-class
Labels for Safety-Aware Trajectory Optimization", T-RO 2022), written from the paper's description.

A kernel perceptron over configurations with the forward-kinematics kernel k(q, q') on the
robot's graph nodes x(q) (:class:`~gdnplan.models.diffco_kernel.FKKernel`). The collision
score is s(q) = Σ_i α_i k(q, q_i) over support points q_i; s > 0 predicts a collision. Its
gradient uses the node Jacobians J_n(q) = ∂x_n/∂q (B, N, 2, dof):

    ∂s/∂q = Σ_i α_i ∂k/∂r² · (2/N) Σ_n (x_n(q) − x_n(q_i))ᵀ J_n(q).

Training is Fastron's perceptron (:func:`~gdnplan.models.diffco_kernel.fastron`) on labels
y = +1 (coal f ≤ margin) or −1. Active learning for a changed environment (DiffCo §IV-D /
Fastron): relabel the support points with coal in the new scene, add Gaussian perturbations
around them (exploitation) and uniform samples (exploration), label those with coal and continue
the perceptron from the old weights. The fitted variant (DiffCo's smooth surrogate for
optimisation) is kernel ridge regression of coal's signed distance over the labelled pool P (the
training or active-learning configurations, at most ``FIT_MAX`` of them) with the same kernel:
w = (K_PP + λI)⁻¹ f_P, f̃(q) = Σ_{j∈P} w_j k(q, q_j). Fitting only the support points, which
all lie on the collision boundary, leaves f̃ ≈ 0 away from it and its gradient pointing the
wrong way.

As a :class:`~gdnplan.models.DistanceModel` DiffCo returns −s (larger = freer), so AUC and ACD
are defined but it is not a distance in metres (``is_distance = False``; MAE is N/A).

DiffCo is tied to the environment it was trained in: it records the obstacle layout of its
training scene (of the scene of its last :meth:`DiffCo.adapt`), and ``distance``,
``distance_and_grad``, ``predict_dataset`` and the CasADi callback (``check_scene``) refuse a
scene of another robot or with other obstacles (:mod:`gdnplan.models.diffco_scene`: the same
polygons in order, every vertex within 1e-6 m) with an InputError naming the fix. The score
of the trained layout in a changed scene (Table I's "DiffCo w/o AL") is asked for explicitly:
``model.ignoring_obstacles()`` is a copy that evaluates any scene of the robot. DiffCo is
not saved to files (it trains in seconds), so no stored model lacks its layout.

Modules: the kernel, its weighted sums (value and gradient) and Fastron in
:mod:`gdnplan.models.diffco_kernel`, the robot and layout checks in
:mod:`gdnplan.models.diffco_scene`; this module re-exports their names.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ..distance import signed_distance
from ..errors import InputError
from ..limits import check_int
from ..robot import make_rng
from ..scene import Scene, check_scene
from .diffco_kernel import CHUNK as CHUNK
from .diffco_kernel import FKKernel, fastron, kernel_sum, kernel_sum_and_grad
from .diffco_scene import (
    LAYOUT_TOL,
    dataset_difference,
    layout_difference,
    layout_of,
    same_kinematics,
    stale_layout_error,
    unknown_layout_error,
)
from .fields import check_real
from .settings import check_flag

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
        obstacles: the obstacle polygons (m_i, 2) (m) of the training scene, or of the scene of
            the last :meth:`adapt` (read-only copies); None when unknown (a DiffCo built
            directly), which refuses every scene unless ``ignore_obstacles``.
        ignore_obstacles: False (the default) refuses a scene whose obstacles are not
            ``obstacles`` (module docstring); True (:meth:`ignoring_obstacles`) evaluates the
            trained layout's score in any scene of the robot.
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
    obstacles: tuple[np.ndarray, ...] | None = None
    ignore_obstacles: bool = False
    is_distance = False

    def __post_init__(self) -> None:
        check_flag(self.ignore_obstacles, "ignore_obstacles")
        if self.obstacles is not None:
            if not isinstance(self.obstacles, (tuple, list)):
                raise InputError(
                    f"obstacles: expected a sequence of polygons (m, 2) or None, got "
                    f"{type(self.obstacles).__name__}"
                )
            polys = layout_of(self.obstacles)
            if any(p.ndim != 2 or p.shape[1] != 2 or not np.isfinite(p).all() for p in polys):
                raise InputError("obstacles: expected finite polygons of shape (m, 2) (m)")
            object.__setattr__(self, "obstacles", polys)

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
        :data:`MAX_POOL`; the other settings: :func:`check_training`); the model records
        ``scene``'s obstacles and refuses scenes with others."""
        check_scene(scene, "planar")
        check_int(n, "n", 1, MAX_POOL, "the kernel matrix is n² numbers")
        check_training(gamma, beta, margin, max_iter)
        kernel = FKKernel(scene.robot, float(gamma))
        q = scene.robot.sample(n, seed=seed)
        d = signed_distance(scene, q)
        model = cls(
            kernel, q[:0], np.zeros(0), q, d, beta=beta, margin=margin, obstacles=scene.obstacles
        )
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
            A new DiffCo (perceptron score; call :meth:`fitted` for the surrogate) that
            records ``scene``'s obstacles and checks them (``ignore_obstacles`` False: the
            copy is for ``scene``, not a stale layout).
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
        new = replace(self, obstacles=scene.obstacles, ignore_obstacles=False)
        return new._fit(q, d, alpha0, max_iter)

    def ignoring_obstacles(self) -> DiffCo:
        """A copy that evaluates any scene of its robot with the trained layout's score, the
        scene's obstacles unused (Table I's "DiffCo w/o AL"): the explicit opt-in to a model
        that does not know the scene it is given (module docstring)."""
        return replace(self, ignore_obstacles=True)

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

    def check_scene(self, scene: Scene) -> None:
        """InputError unless ``scene`` is a planar scene of this robot (:meth:`check_robot`)
        among the recorded obstacles (:func:`~gdnplan.models.diffco_scene.layout_difference`;
        any obstacles when ``ignore_obstacles``)."""
        self.check_robot(scene)
        if self.ignore_obstacles:
            return
        if self.obstacles is None:
            raise unknown_layout_error()
        why = layout_difference(self.obstacles, scene.obstacles)
        if why is not None:
            raise stale_layout_error("scene", why)

    def distance(self, scene: Scene, q: np.ndarray) -> np.ndarray:
        """(B,) −s(q) (or the fitted surrogate) at q (B, dof) (rad) in ``scene``, a scene of
        the training robot and obstacles (:meth:`check_scene`)."""
        self.check_scene(scene)
        return kernel_sum(self.kernel, self.centers, self.weights, scene.robot.check_q(q))

    def predict_dataset(self, ds, grad: bool) -> tuple[np.ndarray, np.ndarray | None]:
        """A dataset's (:class:`gdnplan.data.Dataset`) samples in one pass: (n,) values and,
        with ``grad``, (n, dof) gradients. Every sample's robot must be the training robot
        and, unless ``ignore_obstacles``, its obstacles the recorded ones (InputError naming
        the first sample that differs)."""
        for rows in ds.variants().values():
            if len(rows):
                self.check_robot(Scene(ds.robot(int(rows[0])), ()))
        if not self.ignore_obstacles:
            if self.obstacles is None:
                raise unknown_layout_error()
            bad = dataset_difference(self.obstacles, ds.obstacles, ds.sizes)
            if bad is not None:
                raise stale_layout_error(f"dataset sample {bad[0]}", bad[1])
        fit = (self.kernel, self.centers, self.weights, self.kernel.robot.check_q(ds.q))
        return kernel_sum_and_grad(*fit) if grad else (kernel_sum(*fit), None)

    def distance_and_grad(self, scene: Scene, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """((B,), (B, dof)) the value and its exact gradient through the node Jacobians at q
        (B, dof) (rad) in ``scene``, a scene of the training robot and obstacles
        (:meth:`check_scene`)."""
        self.check_scene(scene)
        q = scene.robot.check_q(q)
        return kernel_sum_and_grad(self.kernel, self.centers, self.weights, q)


__all__ = [
    "CHUNK",
    "FIT_MAX",
    "LAYOUT_TOL",
    "MAX_FASTRON_ITER",
    "MAX_POOL",
    "DiffCo",
    "FKKernel",
    "check_training",
    "fastron",
    "same_kinematics",
]
