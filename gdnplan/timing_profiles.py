"""The motion profiles of a timed path (:mod:`gdnplan.timing`): q, q̇ and q̈ at times t.

:class:`LinearProfile` (``linear``: the waypoint polygon at constant speed per segment),
:class:`StopProfile` (``stop``: rest-to-rest trapezoids on every segment) and
:class:`SmoothProfile` (``smooth``: the PCHIP curve under toppra's s(t), built by
:func:`gdnplan.timing_toppra.toppra_profile`); each has ``state(t)`` for times t (N,) in
[0, duration] (s).
"""

from __future__ import annotations

import numpy as np


def _segment_of(times: np.ndarray, t: np.ndarray) -> np.ndarray:
    return np.clip(np.searchsorted(times, t, side="right") - 1, 0, max(len(times) - 2, 0))


class LinearProfile:
    def __init__(self, q: np.ndarray, v: np.ndarray):
        self.q, self.step = q, np.diff(q, axis=0)
        tau = np.max(np.abs(self.step) / v, axis=1) if len(q) > 1 else np.zeros(0)
        self.times = np.concatenate([[0.0], np.cumsum(tau)])
        self.tau = tau

    def state(self, t):
        if len(self.q) == 1:
            z = np.zeros((len(t), self.q.shape[1]))
            return self.q[[0] * len(t)], z, z
        k = _segment_of(self.times, t)
        tau = self.tau[k][:, None]
        # divided, not multiplied by 1/τ: a denormal τ (a step of ~1e-300 rad) has no finite
        # reciprocal, while Δq/τ stays within the velocity limit
        elapsed = (t - self.times[k])[:, None]
        with np.errstate(over="ignore"):
            frac = np.divide(elapsed, tau, out=np.zeros_like(elapsed), where=tau > 0)
        frac = np.clip(frac, 0.0, 1.0)
        moving = (tau > 0) & (t < self.times[-1])[:, None]
        qd = np.divide(self.step[k], tau, out=np.zeros_like(self.step[k]), where=moving)
        return self.q[k] + frac * self.step[k], qd, np.zeros_like(qd)


class StopProfile:
    """Rest-to-rest trapezoidal profile σ(t) on every segment q_k + σ Δq_k."""

    def __init__(self, q: np.ndarray, v: np.ndarray, a: np.ndarray):
        self.q, self.step = q, np.diff(q, axis=0)
        size = np.abs(self.step)
        with np.errstate(divide="ignore", over="ignore"):  # a tiny step: no motion
            vs = np.min(v / size, axis=1, initial=np.inf) if len(size) else np.zeros(0)
            acc = np.min(a / size, axis=1, initial=np.inf) if len(size) else np.zeros(0)
        moving = np.isfinite(vs)
        vs, acc = np.where(moving, vs, 1.0), np.where(moving, acc, 1.0)
        triangle = vs**2 >= acc
        self.peak = np.where(triangle, np.sqrt(acc), vs)
        self.acc, self.ramp = acc, self.peak / acc
        self.tau = np.where(moving, np.where(triangle, 2 * self.ramp, 1 / vs + vs / acc), 0.0)
        self.times = np.concatenate([[0.0], np.cumsum(self.tau)])

    def state(self, t):
        if len(self.q) == 1:
            z = np.zeros((len(t), self.q.shape[1]))
            return self.q[[0] * len(t)], z, z
        k = _segment_of(self.times, t)
        x = np.clip(t - self.times[k], 0.0, self.tau[k])
        acc, peak, ramp, tau = self.acc[k], self.peak[k], self.ramp[k], self.tau[k]
        rest = tau - x
        up, down = x < ramp, rest < ramp
        sig = np.where(up, 0.5 * acc * x**2, 0.5 * acc * ramp**2 + peak * (x - ramp))
        sig = np.where(down & ~up, 1.0 - 0.5 * acc * rest**2, sig)
        sd = np.where(up, acc * x, np.where(down, acc * rest, peak))
        sdd = np.where(up, acc, np.where(down, -acc, 0.0))
        sig, sd, sdd = (np.where(tau > 0, y, 0.0)[:, None] for y in (sig, sd, sdd))
        return self.q[k] + sig * self.step[k], sd * self.step[k], sdd * self.step[k]


class SmoothProfile:
    """PCHIP path p(s) with toppra's s(t): ṡ² linear in s on each grid cell, time stretch c."""

    def __init__(self, curve, grid, sd, stretch: float = 1.0):
        self.p, self.dp, self.ddp = curve, curve.derivative(), curve.derivative(2)
        self.grid, self.sd, self.c = grid, sd, stretch
        dg = np.diff(grid)
        self.u = (sd[1:] ** 2 - sd[:-1] ** 2) / (2 * dg)
        self.ts = np.concatenate([[0.0], np.cumsum(2 * dg / (sd[1:] + sd[:-1]))])

    def at_grid(self, cell: np.ndarray, x: np.ndarray):
        """(s, ṡ, s̈) at time x after the start of grid cell ``cell`` (toppra's time)."""
        sd, u = self.sd[cell], self.u[cell]
        s = np.minimum(self.grid[cell] + sd * x + 0.5 * u * x**2, self.grid[cell + 1])
        return s, sd + u * x, u

    def derivatives(self, s, sd, sdd):
        dp = self.dp(s)
        return self.p(s), dp * sd[:, None], self.ddp(s) * (sd**2)[:, None] + dp * sdd[:, None]

    def state(self, t):
        tt = t / self.c
        cell = _segment_of(self.ts, tt)
        q, qd, qdd = self.derivatives(*self.at_grid(cell, tt - self.ts[cell]))
        return q, qd / self.c, qdd / self.c**2


__all__ = ["LinearProfile", "SmoothProfile", "StopProfile"]
