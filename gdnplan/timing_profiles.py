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
    """Rest-to-rest trapezoidal profile σ(t) on every segment q_k + σ Δq_k.

    Per segment, t_v = max_j |Δq_j| / v_j (s: the segment at the velocity limit) and
    t_a² = max_j |Δq_j| / a_j (s²: 1/σ̈_max). A triangle (t_a² ≥ t_v²) ramps for r = t_a and
    lasts τ = 2r; a trapezoid ramps for r = t_a²/t_v, cruises at σ̇ = 1/t_v and lasts
    τ = t_v + r. Each ramp covers h = r / (2 t_p) of the segment (t_p = r for a triangle,
    t_v for a trapezoid: σ̇_peak = 1/t_p). Velocities and accelerations are formed as
    Δq / t_p and Δq / t_a², never as σ̇ Δq: σ̇ and σ̈ overflow for denormal steps while
    those quotients stay within the limits.
    """

    def __init__(self, q: np.ndarray, v: np.ndarray, a: np.ndarray):
        self.q, self.step = q, np.diff(q, axis=0)
        size = np.abs(self.step)
        t_v = np.max(size / v, axis=1, initial=0.0)
        t_a2 = np.max(size / a, axis=1, initial=0.0)
        triangle = t_a2 >= t_v**2
        self.ramp = np.where(triangle, np.sqrt(t_a2), _safe_divide(t_a2, t_v))
        self.t_peak = np.where(triangle, self.ramp, t_v)
        self.t_a2 = t_a2
        self.h = np.where(triangle, 0.5, 0.5 * _safe_divide(self.ramp, t_v))
        self.tau = np.where(triangle, 2 * self.ramp, t_v + self.ramp)
        self.times = np.concatenate([[0.0], np.cumsum(self.tau)])

    def state(self, t):
        if len(self.q) == 1:
            z = np.zeros((len(t), self.q.shape[1]))
            return self.q[[0] * len(t)], z, z
        k = _segment_of(self.times, t)
        x = np.clip(t - self.times[k], 0.0, self.tau[k])
        ramp, h, t_peak, tau = self.ramp[k], self.h[k], self.t_peak[k], self.tau[k]
        rest = tau - x
        up, down = x < ramp, rest < ramp
        u, w = _safe_divide(x, ramp), _safe_divide(rest, ramp)
        sig = np.where(up, h * u**2, h + _safe_divide(x - ramp, t_peak))
        sig = np.clip(np.where(down & ~up, 1.0 - h * w**2, sig), 0.0, 1.0)
        speed = np.where(up, u, np.where(down, w, 1.0))
        sign = np.where(up, 1.0, np.where(down, -1.0, 0.0))
        step = self.step[k]
        qd = speed[:, None] * _safe_divide(step, t_peak[:, None])
        qdd = sign[:, None] * _safe_divide(step, self.t_a2[k][:, None])
        still = (tau <= 0)[:, None]
        return (
            self.q[k] + np.where(still, 0.0, sig[:, None] * step),
            np.where(still, 0.0, qd),
            np.where(still, 0.0, qdd),
        )


def _safe_divide(num: np.ndarray, den: np.ndarray) -> np.ndarray:
    """num / den where den > 0, else 0 (a segment without that phase)."""
    num, den = np.broadcast_arrays(np.asarray(num, float), np.asarray(den, float))
    with np.errstate(over="ignore"):
        return np.divide(num, den, out=np.zeros(num.shape), where=den > 0)


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
