"""Input checks of robot calls: joint-angle batches, joint-limit lookups and random seeds.

Joint angles are real numbers (numpy kinds integer, unsigned or float), never booleans,
strings or complex numbers, and finite; a seed is what ``numpy.random.default_rng`` takes
(None, an integer ≥ 0 or a non-empty list of them) or a ``numpy.random.Generator``. Anything
else is an :class:`~gdnplan.errors.InputError` naming the argument.
"""

from __future__ import annotations

import numpy as np

from .errors import InputError


def first_outside(q: np.ndarray, lower: np.ndarray, upper: np.ndarray, tol: float = 1e-9):
    """Index of the first joint of q (dof,) outside [lower − tol, upper + tol], or None."""
    out = np.flatnonzero((q < lower - tol) | (q > upper + tol))
    return int(out[0]) if out.size else None


_KINDS = {"b": "booleans", "U": "strings", "S": "bytes", "c": "complex numbers", "O": "objects"}


def as_batch(q, dof: int, name: str = "q") -> np.ndarray:
    """Return q as a C-contiguous float64 (B, dof) array; a single (dof,) configuration becomes
    (1, dof) (a view of a negative-stride or Fortran-order q was refused by torch.as_tensor).

    InputError naming ``name`` unless q holds real numbers (numpy kinds integer, unsigned or
    float): booleans, strings, complex numbers and other objects are refused, not coerced
    (``"0.1"`` is no angle, ``True`` no 1 rad, 1 + 2j loses its imaginary part), and so are a
    masked array with masked entries (numpy would read the hidden values) and a torch tensor
    that requires grad (the distance functions return numpy: detach it first).
    """
    if isinstance(q, np.ma.MaskedArray) and np.ma.is_masked(q):
        raise InputError(f"{name}: masked entries are no joint angles; fill them (q.filled(…))")
    try:
        arr = np.asarray(q)
    except (TypeError, ValueError, RuntimeError) as e:  # RuntimeError: torch's requires_grad
        hint = "; a torch tensor that requires grad: pass q.detach()" if _needs_grad(q) else ""
        raise InputError(f"{name}: expected numbers, got {type(q).__name__}{hint}") from e
    if arr.dtype.kind not in "iuf" or _holds_bool(q):
        kind = "b" if arr.dtype.kind in "iuf" else arr.dtype.kind
        what = _KINDS.get(kind, f"an array of {arr.dtype}")
        raise InputError(f"{name}: expected real numbers (rad), got {what}")
    if arr.ndim not in (1, 2) or arr.shape[-1] != dof:
        raise InputError(f"{name}: expected shape (B, {dof}) or ({dof},), got {arr.shape}")
    q = np.ascontiguousarray(arr, dtype=float).reshape(-1, dof)  # torch takes no negative strides
    if not np.all(np.isfinite(q)):
        raise InputError(f"{name}: contains NaN or infinite values")
    return q


def one_q(q, dof: int, name: str = "q") -> np.ndarray:
    """One configuration as float64 (dof,): the checks of :func:`as_batch`, and one row only
    (a (B, dof) batch is refused, not read as its first row); a float64 (dof,) array that is
    finite passes as it is (the kinematics' per-configuration calls)."""
    if type(q) is np.ndarray and q.dtype == np.float64 and q.shape == (dof,):
        if np.isfinite(q).all():
            return q
    arr = as_batch(q, dof, name)
    if len(arr) != 1:
        raise InputError(f"{name}: expected one configuration ({dof},), got {len(arr)} of them")
    return arr[0]


def check_pairs(robot, qa, qb) -> np.ndarray:
    """qb − qa (B, dof) of two batches of ``robot``'s configurations (``robot.check_q``: real,
    finite, dof columns) of equal length, or one of them a single configuration; else
    InputError naming them (numpy raised its broadcast error, or dropped a complex part)."""
    qa, qb = robot.check_q(qa, "qa"), robot.check_q(qb, "qb")
    if len(qa) != len(qb) and 1 not in (len(qa), len(qb)):
        raise InputError(
            f"qa, qb: expected as many configurations on each side, got {len(qa)} and {len(qb)}"
        )
    return qb - qa


MAX_JOINT_LIMIT = 1e3  # rad: |lower|, |upper| of a robot's joint (as a URDF's, joint_limits)


def check_joint_range(lower, upper, dof: int, name: str = "limits") -> tuple:
    """(lower, upper) as read-only float64 (dof,) arrays of finite real numbers within
    ±:data:`MAX_JOINT_LIMIT` rad with lower < upper, else InputError naming ``name`` (a
    robot built with limits of another joint count, reversed, NaN or complex ones was
    accepted and planned with them)."""
    out = []
    for which, value in (("lower", lower), ("upper", upper)):
        arr = as_batch(value, dof, f"{name} {which}")
        if len(arr) != 1 or np.max(np.abs(arr)) > MAX_JOINT_LIMIT:
            raise InputError(
                f"{name} {which}: expected {dof} joint limits within ±{MAX_JOINT_LIMIT:g} rad"
            )
        arr = arr[0].copy()
        arr.setflags(write=False)
        out.append(arr)
    bad = np.flatnonzero(out[0] >= out[1])
    if bad.size:
        j = int(bad[0])
        raise InputError(
            f"{name}: joint {j} has lower {out[0][j]:g} ≥ upper {out[1][j]:g}; give lower < upper"
        )
    return tuple(out)


def _needs_grad(q) -> bool:
    return bool(getattr(q, "requires_grad", False))


def _holds_bool(q) -> bool:
    """True when a (nested) list or tuple holds a boolean: numpy reads [True, 0.5] as float64
    and the boolean vanishes, so the elements themselves are looked at."""
    if not isinstance(q, (list, tuple)):
        return False
    return any(isinstance(x, (bool, np.bool_)) for x in np.asarray(q, dtype=object).ravel())


def check_seed(seed, name: str = "seed"):
    """A seed numpy's ``default_rng`` takes, else InputError: None (fresh entropy), an integer
    ≥ 0 or a non-empty sequence of them; booleans are refused (``True`` is no seed)."""
    if seed is None:
        return None
    items = seed if isinstance(seed, (list, tuple)) and seed else [seed]
    for x in items:
        if isinstance(x, (bool, np.bool_)) or not isinstance(x, (int, np.integer)) or x < 0:
            raise InputError(
                f"{name}: expected None, an integer ≥ 0 or a list of them, got {seed!r}"
            )
    return seed


def make_rng(seed, name: str = "seed") -> np.random.Generator:
    """The generator of ``seed``: a ``numpy.random.Generator`` itself (drawn from directly, its
    stream continues, as ``np.random.default_rng(generator)`` does), else
    ``np.random.default_rng`` of a seed :func:`check_seed` allows (InputError otherwise)."""
    if isinstance(seed, np.random.Generator):
        return seed
    return np.random.default_rng(check_seed(seed, name))


__all__ = [
    "MAX_JOINT_LIMIT",
    "as_batch",
    "check_joint_range",
    "check_pairs",
    "check_seed",
    "first_outside",
    "make_rng",
    "one_q",
]
