"""A DistanceModel as a CasADi function with an exact, block-diagonal Jacobian.

:class:`DistanceCallback` maps the stacked configurations ``x = vec(Q)``, ``Q`` of shape (K, dof)
(row-major: x[k·dof + j] = Q[k, j]), to the K·R distances ``y[k·R + r] = d_r(Q[k])`` — R = 1
for the overall minimum, R = n_links for one row per link polygon. Every distance depends only on
its own configuration, so

    ∂y/∂x = blockdiag(G_0, …, G_{K−1}),   G_k = ∂d(Q[k])/∂q  of shape (R, dof),

and one batched ``distance_and_grad`` call yields both the values and the Jacobian. The last
(x, y, ∂y/∂x) is cached: Ipopt asks for the value and the Jacobian at the same point, which then
costs one model pass. A model with ``distance_deferred_grad`` (GraphDistNet) computes the
Jacobian only when Ipopt asks for it: the line search's rejected trial points then cost a
forward pass alone (docs/decisions.md#deferred-gradients). Build the NLP with MX symbols (SX
would call the callback per nonzero).
"""

from __future__ import annotations

import inspect
import re
from collections.abc import Callable
from dataclasses import dataclass

import casadi
import numpy as np

from .distance import checker, witness_gradient
from .errors import InputError
from .flags import check_flag
from .limits import check_int, is_number
from .models import CoalModel, DistanceModel
from .scene import Scene, check_scene

BatchFn = Callable[[np.ndarray], tuple[np.ndarray, Callable[[], np.ndarray]]]


def supports_per_link(model: DistanceModel) -> bool:
    """True when the model's ``distance_and_grad`` takes ``per_link`` (coal always does)."""
    return isinstance(model, CoalModel) or _takes(model, "per_link")


def _takes(model: DistanceModel, name: str) -> bool:
    """True when the model's ``distance_and_grad`` has a parameter ``name``."""
    try:
        return name in inspect.signature(model.distance_and_grad).parameters
    except (TypeError, ValueError):
        return False


def distance_rows(
    model: DistanceModel, scene: Scene, per_link: bool = False, cap: float = np.inf
) -> tuple[BatchFn, int]:
    """The batched function q (B, dof) -> (d (B, R), a function returning ∂d/∂q (B, R, dof))
    and its row count R.

    The gradient is computed when that function is called if the model has
    ``distance_deferred_grad``, else together with d. With ``per_link`` there is one row per
    link polygon; distances above ``cap`` (m) report ``cap`` with a zero gradient (an inactive
    constraint; coal skips those pairs entirely). Raises InputError when the model has no
    per-link distances.
    """
    if per_link and not supports_per_link(model):
        raise InputError(f"per_link: model {model.name!r} has no per-link distances")
    if not per_link:
        deferred = getattr(model, "distance_deferred_grad", None)

        def overall(q: np.ndarray) -> tuple[np.ndarray, Callable[[], np.ndarray]]:
            if deferred is not None:
                d, grad = deferred(scene, q)
                return np.asarray(d, float)[:, None], lambda: np.asarray(grad(), float)[:, None]
            d, g = model.distance_and_grad(scene, q)
            return np.asarray(d, float)[:, None], _given(np.asarray(g, float)[:, None, :])

        return overall, 1
    if isinstance(model, CoalModel):

        def coal_links(q: np.ndarray) -> tuple[np.ndarray, Callable[[], np.ndarray]]:
            w = checker(scene).closest(q, per_link=True, cap=cap)
            return w.distance, _given(witness_gradient(scene, q, w))

        return coal_links, scene.robot.n_links

    capped = _takes(model, "cap")  # the model skips the pairs beyond the cap itself

    def links(q: np.ndarray) -> tuple[np.ndarray, Callable[[], np.ndarray]]:
        d, g = model.distance_and_grad(scene, q, per_link=True, **({"cap": cap} if capped else {}))
        d = np.asarray(d, float)
        return np.minimum(d, cap), _given(np.asarray(g, float) * (d < cap)[..., None])

    return links, scene.robot.n_links


def _given(g: np.ndarray) -> Callable[[], np.ndarray]:
    """A gradient already computed, as the function :func:`distance_rows` returns."""
    return lambda: g


@dataclass
class _Cache:
    """Last evaluated point x, its values (K·R,), the function giving ∂d/∂q (K, R, dof) and,
    once asked for, the Jacobian nonzeros (CCS order)."""

    x: np.ndarray | None = None
    y: np.ndarray | None = None
    grad: Callable[[], np.ndarray] | None = None
    nz: np.ndarray | None = None


def block_sparsity(k: int, rows: int, dof: int) -> casadi.Sparsity:
    """Sparsity of blockdiag of k dense (rows, dof) blocks: shape (k·rows, k·dof)."""
    return casadi.kron(casadi.Sparsity.diag(k), casadi.Sparsity.dense(rows, dof))


MAX_POINTS = 10**6  # n_points: configurations of one callback call
_CASADI_NAME = re.compile(r"[A-Za-z][A-Za-z0-9_]*\Z")


def check_callback(name, model, scene, n_points, per_link, cap) -> None:
    """InputError naming the first bad argument of :class:`DistanceCallback`: ``name`` a
    CasADi name (a letter, then letters, digits, _), ``model`` a distance model fit for
    ``scene`` (its ``check_scene``), ``n_points`` an integer in 1 … :data:`MAX_POINTS`,
    ``per_link`` a bool, ``cap`` a number > 0 (m; +inf: no cap)."""
    if not isinstance(name, str) or not _CASADI_NAME.match(name):
        raise InputError(
            f"name: expected a CasADi name (a letter, then letters, digits, _), got {name!r}"
        )
    check_scene(scene, "any", name="scene")
    if not callable(getattr(model, "distance_and_grad", None)):
        raise InputError(f"model: expected a distance model (gdnplan.models), got {model!r}")
    if callable(getattr(model, "check_scene", None)):
        model.check_scene(scene)
    check_int(n_points, "n_points", 1, MAX_POINTS)
    check_flag(per_link, "per_link")
    if not is_number(cap) or not cap > 0:
        raise InputError(f"cap: expected a number > 0 (m) or inf, got {cap!r}")


class DistanceCallback(casadi.Callback):
    """CasADi function x (K·dof,) -> distances (K·R,), one batched model call per new x.

    Attributes:
        n_points: K, configurations per call.
        dof: joints per configuration.
        rows: R, distances per configuration.
        model_calls: batched model calls so far (one per new x).
        gradient_calls: of these, the calls whose Jacobian was asked for.
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
        check_callback(name, model, scene, n_points, per_link, cap)
        casadi.Callback.__init__(self)
        self.n_points, self.dof = int(n_points), scene.robot.dof
        self.fn, self.rows = distance_rows(model, scene, per_link, cap)
        self.model_calls = 0
        self.gradient_calls = 0
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
    def values(self, x: np.ndarray) -> np.ndarray:
        """Distances (K·R,) at x (K·dof,): one model call per new x, from the cache otherwise."""
        x = np.asarray(x, float).ravel()
        if x.size != self.n_points * self.dof:
            raise InputError(
                f"x: expected {self.n_points}·{self.dof} = {self.n_points * self.dof} values "
                f"(configurations × dof), got {x.size}"
            )
        c = self._cache
        if not np.all(np.isfinite(x)):  # Ipopt's trial point went bad: NaN, and it backtracks
            nan = np.full(self.n_points * self.rows, np.nan)
            grad = np.full((self.n_points, self.rows, self.dof), np.nan)
            self._cache = _Cache(x.copy(), nan, _given(grad))
            return nan
        if c.x is None or not np.array_equal(c.x, x):
            d, grad = self.fn(x.reshape(self.n_points, self.dof))
            self.model_calls += 1
            self._cache = c = _Cache(x.copy(), d.ravel(), grad)
        return c.y

    def jacobian_nonzeros(self, x: np.ndarray) -> np.ndarray:
        """Nonzeros (K·dof·R,) of ∂y/∂x at x in CCS order (column (k, j), then row r)."""
        self.values(x)
        c = self._cache
        if c.nz is None:
            c.nz = np.swapaxes(c.grad(), 1, 2).ravel()
            self.gradient_calls += 1
        return c.nz

    def evaluate(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Values (K·R,) and Jacobian nonzeros (K·dof·R,) at x, from the cache when x repeats."""
        return self.values(x), self.jacobian_nonzeros(x)

    def eval(self, arg):
        return [casadi.DM(self.values(np.asarray(arg[0])))]

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
        nz = self.parent.jacobian_nonzeros(np.asarray(arg[0]))
        return [casadi.DM(self.sparsity, nz)]


__all__ = ["DistanceCallback", "block_sparsity", "distance_rows", "supports_per_link"]
