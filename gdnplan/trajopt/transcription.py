"""The Ipopt NLP of the package docstring (direct transcription) for one set of check points,
built with CasADi; the distance rows are one batched call of the model
(:class:`~gdnplan.casadi_bridge.DistanceCallback`)."""

from __future__ import annotations

import casadi
import numpy as np

from ..casadi_bridge import DistanceCallback
from ..errors import InputError
from ..models import DistanceModel
from .check_points import _interpolation_matrix, _path_parameters
from .config import IpoptConfig
from .interrupt import StopOnInterrupt, interruptible
from .problem import Problem

WARM_START_OPTIONS = {  # Ipopt options of refine rounds started from the last primal-dual point
    "warm_start_init_point": "yes",
    "mu_init": 1e-4,
    "warm_start_bound_push": 1e-6,
    "warm_start_slack_bound_push": 1e-6,
    "warm_start_mult_bound_push": 1e-6,
}


class _Transcription:
    """The NLP of the package docstring for one set of check points (segment t split in
    ``splits[t]`` pieces); rebuilt when the certificate refines them."""

    def __init__(
        self,
        problem: Problem,
        model: DistanceModel,
        goal,
        opts: IpoptConfig,
        splits: np.ndarray,
        margin: float | np.ndarray,
        warm: bool = False,
    ):
        robot = problem.scene.robot
        T, n = problem.waypoints, robot.dof
        self.problem, self.goal, self.T, self.splits = problem, goal, T, splits
        self.duals: tuple[np.ndarray, np.ndarray] | None = None
        x = casadi.MX.sym("x", (T - 2) * n)
        Q = casadi.vertcat(
            casadi.DM(problem.start).T, casadi.reshape(x, n, T - 2).T, casadi.DM(goal).T
        )  # (T, n)
        inner = slice(1, -1)  # the fixed start and goal are no rows (package docstring)
        W = casadi.sparsify(casadi.DM(_interpolation_matrix(splits)[inner]))  # (K, T)
        P = casadi.mtimes(W, Q)  # (K, n) check points along the path
        K = W.shape[0]
        self.callback = DistanceCallback(
            "distance", model, problem.scene, K, opts.per_link, opts.link_cap
        )
        rows = self.callback.rows
        d = self.callback(casadi.reshape(P.T, K * n, 1))  # (K·R,)
        steps = Q[1:, :] - Q[:-1, :]  # (T−1, n)
        g = casadi.vertcat(d, casadi.reshape(steps, (T - 1) * n, 1))
        n_steps = (T - 1) * n
        margins = np.repeat(np.broadcast_to(margin, (K,)), rows)  # check point by check point
        self.lbg = np.concatenate([margins, np.full(n_steps, -problem.max_step)])
        self.ubg = np.concatenate([np.full(K * rows, np.inf), np.full(n_steps, problem.max_step)])
        self.lbx = np.tile(problem.lower, T - 2)
        self.ubx = np.tile(problem.upper, T - 2)
        f = casadi.sumsqr(steps)
        ipopt = {
            "hessian_approximation": "limited-memory",
            # L-BFGS's initial matrix σ I with σ = sᵀy / sᵀs of the last step (Ipopt's
            # "scalar2"): the line search then rarely backtracks, so fewer constraint
            # evaluations (docs/decisions.md#l-bfgs-initial-matrix)
            "limited_memory_initialization": "scalar2",
            "print_level": 0,
            "max_iter": opts.max_iter,
            "tol": opts.tol,
            "acceptable_tol": 1e3,  # stop on objective stagnation + feasibility
            "acceptable_iter": 3,
            "acceptable_obj_change_tol": opts.obj_change_tol,
            "acceptable_constr_viol_tol": 1e-5,
            "mu_strategy": "adaptive",
            "sb": "yes",  # no banner: stdout stays clean for --json
        }
        ipopt.update(opts.options)
        if warm:  # a refine round: start from the last round's primal-dual point
            ipopt.update(WARM_START_OPTIONS)
        self.stop = StopOnInterrupt(x.numel(), g.numel())  # Ctrl-C: stop at the next iteration
        settings = {"print_time": False, "error_on_fail": False, "iteration_callback": self.stop}
        try:
            nlp = {"x": x, "f": f, "g": g}
            self.solver = casadi.nlpsol("trajopt", "ipopt", nlp, {"ipopt": ipopt, **settings})
        except RuntimeError as e:  # limits.check_ipopt keeps Ipopt's ranges: not expected
            raise InputError(
                f"ipopt.options: Ipopt refused the options {opts.options!r} "
                f"({str(e).splitlines()[-1][:200]}); see docs/problem_file.md#ipoptoptions"
            ) from e

    def solve(
        self, guess: np.ndarray, duals: tuple[np.ndarray, np.ndarray] | None = None
    ) -> tuple[np.ndarray, dict]:
        """Solve from an initial guess (T, dof) and, for a warm start, multipliers
        (λ_g, λ_x); returns the waypoints (T, dof) and Ipopt stats."""
        x0 = np.clip(guess[1:-1], self.problem.lower, self.problem.upper).ravel()
        bounds = {"lbx": self.lbx, "ubx": self.ubx, "lbg": self.lbg, "ubg": self.ubg}
        if duals is not None:
            bounds.update(lam_g0=duals[0], lam_x0=duals[1])
        try:
            with interruptible():  # Ctrl-C: Ipopt stops, then KeyboardInterrupt here
                sol = self.solver(x0=x0, **bounds)
        except RuntimeError as e:
            return guess, {"return_status": f"exception: {str(e).splitlines()[-1]}"[:200]}
        self.duals = (np.asarray(sol["lam_g"]).ravel(), np.asarray(sol["lam_x"]).ravel())
        inner = np.asarray(sol["x"]).reshape(self.T - 2, -1)
        stats = self.solver.stats()
        return np.vstack([self.problem.start, inner, self.goal]), stats

    def duals_on(self, refined: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
        """The last solution's multipliers (λ_g, λ_x) for the NLP with check points ``refined``
        (a refinement of ``self.splits``): check points of both keep their distance rows'
        multipliers, new ones start at 0; step rows and bounds keep theirs."""
        if self.duals is None:
            return None
        lam_g, lam_x = self.duals
        old, new = _path_parameters(self.splits)[1:-1], _path_parameters(refined)[1:-1]
        rows = self.callback.rows
        lam_d = lam_g[: len(old) * rows].reshape(len(old), rows)
        where = dict(zip(old.tolist(), range(len(old)), strict=True))
        lam_new = np.zeros((len(new), rows))
        for i, s_i in enumerate(new.tolist()):
            if s_i in where:
                lam_new[i] = lam_d[where[s_i]]
        return np.concatenate([lam_new.ravel(), lam_g[len(old) * rows :]]), lam_x
