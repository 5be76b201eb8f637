"""A DistanceModel as a CasADi function with an exact, block-diagonal Jacobian.

:class:`DistanceCallback` maps the stacked configurations ``x = vec(Q)``, ``Q`` of shape (K, dof)
(row-major: x[k·dof + j] = Q[k, j]), to the K·R distances ``y[k·R + r] = d_r(Q[k])`` — R = 1
for the overall minimum, R = n_links for one row per link polygon. Every distance depends only on
its own configuration, so

    ∂y/∂x = blockdiag(G_0, …, G_{K−1}),   G_k = ∂d(Q[k])/∂q  of shape (R, dof),

and one batched ``distance_and_grad`` call yields both the values and the Jacobian. The last
(x, y, ∂y/∂x) is cached: Ipopt asks for the value and the Jacobian at the same point, which then
costs one model pass. Build the NLP with MX symbols (SX would call the callback per nonzero).
"""

from __future__ import annotations

import inspect
from collections.abc import Callable
from dataclasses import dataclass

import casadi
import numpy as np

from .distance import checker, witness_gradient
from .errors import InputError
from .models import CoalModel, DistanceModel
from .scene import Scene

BatchFn = Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]]


def supports_per_link(model: DistanceModel) -> bool:
    """True when the model's ``distance_and_grad`` takes ``per_link`` (coal always does)."""
    if isinstance(model, CoalModel):
        return True
    try:
        return "per_link" in inspect.signature(model.distance_and_grad).parameters
    except (TypeError, ValueError):
        return False


def distance_rows(
    model: DistanceModel, scene: Scene, per_link: bool = False, cap: float = np.inf
) -> tuple[BatchFn, int]:
    """The batched function q (B, dof) -> (d (B, R), ∂d/∂q (B, R, dof)) and its row count R.

    With ``per_link`` there is one row per link polygon; distances above ``cap`` (m) report
    ``cap`` with a zero gradient (an inactive constraint; coal skips those pairs entirely).
    Raises InputError when the model has no per-link distances.
    """
    if per_link and not supports_per_link(model):
        raise InputError(f"per_link: model {model.name!r} has no per-link distances")
    if not per_link:

        def overall(q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
            d, g = model.distance_and_grad(scene, q)
            return np.asarray(d, float)[:, None], np.asarray(g, float)[:, None, :]

        return overall, 1
    if isinstance(model, CoalModel):

        def coal_links(q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
            w = checker(scene).closest(q, per_link=True, cap=cap)
            return w.distance, witness_gradient(scene, q, w)

        return coal_links, scene.robot.n_links

    def links(q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        d, g = model.distance_and_grad(scene, q, per_link=True)
        return np.minimum(np.asarray(d, float), cap), np.asarray(g, float) * (d < cap)[..., None]

    return links, scene.robot.n_links


@dataclass
class _Cache:
    """Last evaluated point and its values (K·R,) and Jacobian nonzeros (CCS order)."""

    x: np.ndarray | None = None
    y: np.ndarray | None = None
    nz: np.ndarray | None = None


def block_sparsity(k: int, rows: int, dof: int) -> casadi.Sparsity:
    """Sparsity of blockdiag of k dense (rows, dof) blocks: shape (k·rows, k·dof)."""
    return casadi.kron(casadi.Sparsity.diag(k), casadi.Sparsity.dense(rows, dof))


class DistanceCallback(casadi.Callback):
    """CasADi function x (K·dof,) -> distances (K·R,), one batched model call per new x.

    Attributes:
        n_points: K, configurations per call.
        dof: joints per configuration.
        rows: R, distances per configuration.
        model_calls: batched ``distance_and_grad`` calls so far.
    """

    def __init__(
        self,
        name: str,
        model: DistanceModel,
        scene: Scene,
        n_points: int,
        per_link: bool = False,
        cap: float = np.inf,
    ):
        casadi.Callback.__init__(self)
        self.n_points, self.dof = int(n_points), scene.robot.dof
        self.fn, self.rows = distance_rows(model, scene, per_link, cap)
        self.model_calls = 0
        self._cache = _Cache()
        self._jac: _JacobianCallback | None = None  # kept alive: CasADi holds no reference
        self.construct(name, {"enable_fd": False})

    # ------------------------------------------------------------ shapes
    def get_n_in(self) -> int:
        return 1

    def get_n_out(self) -> int:
        return 1

    def get_sparsity_in(self, i: int) -> casadi.Sparsity:
        return casadi.Sparsity.dense(self.n_points * self.dof, 1)

    def get_sparsity_out(self, i: int) -> casadi.Sparsity:
        return casadi.Sparsity.dense(self.n_points * self.rows, 1)

    def has_jac_sparsity(self, oind: int, iind: int) -> bool:
        return True

    def get_jac_sparsity(self, oind: int, iind: int, symmetric: bool) -> casadi.Sparsity:
        return block_sparsity(self.n_points, self.rows, self.dof)

    # ------------------------------------------------------------ evaluation
    def evaluate(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Values (K·R,) and Jacobian nonzeros (K·dof·R,) at x, from the cache when x repeats."""
        x = np.asarray(x, float).ravel()
        if x.size != self.n_points * self.dof:
            raise InputError(
                f"x: expected {self.n_points}·{self.dof} = {self.n_points * self.dof} values "
                f"(configurations × dof), got {x.size}"
            )
        c = self._cache
        if c.x is None or not np.array_equal(c.x, x):
            d, g = self.fn(x.reshape(self.n_points, self.dof))
            self.model_calls += 1
            # CCS order: column (k, j), then row r within block k
            self._cache = c = _Cache(x.copy(), d.ravel(), np.swapaxes(g, 1, 2).ravel())
        return c.y, c.nz

    def eval(self, arg):
        y, _ = self.evaluate(np.asarray(arg[0]))
        return [casadi.DM(y)]

    def has_jacobian(self) -> bool:
        return True

    def get_jacobian(self, name, inames, onames, opts):
        self._jac = _JacobianCallback(name, self, opts)
        return self._jac


class _JacobianCallback(casadi.Callback):
    """(x, y) -> ∂y/∂x with block-diagonal sparsity, served from the parent's cache."""

    def __init__(self, name: str, parent: DistanceCallback, opts: dict):
        casadi.Callback.__init__(self)
        self.parent = parent
        self.sparsity = block_sparsity(parent.n_points, parent.rows, parent.dof)
        self.construct(name, opts)

    def get_n_in(self) -> int:
        return 2

    def get_n_out(self) -> int:
        return 1

    def get_sparsity_in(self, i: int) -> casadi.Sparsity:
        p = self.parent
        return p.get_sparsity_in(0) if i == 0 else p.get_sparsity_out(0)

    def get_sparsity_out(self, i: int) -> casadi.Sparsity:
        return self.sparsity

    def eval(self, arg):
        _, nz = self.parent.evaluate(np.asarray(arg[0]))
        return [casadi.DM(self.sparsity, nz)]


__all__ = ["DistanceCallback", "block_sparsity", "distance_rows", "supports_per_link"]
