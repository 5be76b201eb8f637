"""Checks of a learned model's run settings (dtype, device, chunk, on/off flags), each an
:class:`~gdnplan.errors.InputError` naming the setting, and :func:`placed`: the network on the
requested device and dtype without changing the one the caller passed.

A model's settings are checked whenever they are set, not only by its constructor:
:class:`Checked` attributes (``threads``, ``chunk``, ``contact_offset``) pass the
constructor's check on every assignment, with its message; :class:`Fixed` ones (``dtype``,
``device``: the network was placed in them) refuse a new value, naming the fix.
"""

from __future__ import annotations

import copy
from collections.abc import Callable

import torch

from .. import flags
from ..errors import InputError
from ..limits import check_int

DTYPES = (torch.float32, torch.float64)  # the passes run these (float16 overflows in 3-D)
MAX_CHUNK = 10**6  # configurations of one inference pass


def check_dtype(dtype) -> torch.dtype:
    """``dtype`` when it is torch.float32 or torch.float64, else InputError."""
    if dtype not in DTYPES:
        raise InputError(f"dtype: expected torch.float32 or torch.float64, got {dtype!r}")
    return dtype


def check_device(device) -> torch.device:
    """A CPU device, or a CUDA one where CUDA is available, else InputError."""
    try:
        parsed = torch.device(device)
    except (RuntimeError, TypeError) as e:
        raise InputError(f"device: expected 'cpu' or 'cuda', got {device!r}") from e
    if parsed.type == "cuda" and not torch.cuda.is_available():
        raise InputError("device: CUDA is not available on this machine; use 'cpu'")
    if parsed.type not in ("cpu", "cuda"):
        raise InputError(f"device: expected 'cpu' or 'cuda', got {device!r}")
    return parsed


def check_chunk(chunk) -> int | None:
    """None (one pass) or an integer in 1 … :data:`MAX_CHUNK`, else InputError."""
    return None if chunk is None else check_chunk_size(chunk)


def check_chunk_size(chunk) -> int:
    """An integer in 1 … :data:`MAX_CHUNK` (configurations per pass), else InputError."""
    return check_int(chunk, "chunk", 1, MAX_CHUNK)


def check_flag(value, name: str, optional: bool = False) -> bool | None:
    """True or False, a numpy bool included (or None when ``optional``), as a Python bool, else
    InputError naming ``name``: "yes" or 1 are no settings (:func:`gdnplan.flags.check_flag`)."""
    return flags.check_flag(value, name, optional)


class Checked:
    """A model attribute stored as ``check(value)`` on every assignment (the constructor's
    check: a bad value is an InputError when set, not a failure later, deep in a call)."""

    def __init__(self, check: Callable[[object], object]):
        self.check = check

    def __set_name__(self, owner: type, name: str) -> None:
        self.slot = f"_{name}"

    def __get__(self, obj: object, owner: type | None = None):
        return self if obj is None else getattr(obj, self.slot)

    def __set__(self, obj: object, value: object) -> None:
        setattr(obj, self.slot, self.check(value))


class Fixed:
    """A model attribute set once, by its constructor (after its check); any later assignment
    is an InputError: the network and its caches were built for the first value."""

    def __set_name__(self, owner: type, name: str) -> None:
        self.name, self.slot, self.owner = name, f"_{name}", owner.__name__

    def __get__(self, obj: object, owner: type | None = None):
        return self if obj is None else getattr(obj, self.slot)

    def __set__(self, obj: object, value: object) -> None:
        if hasattr(obj, self.slot):
            raise InputError(
                f"{self.name}: fixed when the model is made (its network was placed in "
                f"{getattr(obj, self.slot)}); make another: {self.owner}(model.net, "
                f"{self.name}={value!r}, …)"
            )
        setattr(obj, self.slot, value)


def placed(net: torch.nn.Module, device: torch.device, dtype: torch.dtype) -> torch.nn.Module:
    """``net`` in eval mode on ``device`` and ``dtype``: itself when it is there already, else
    a copy (``Module.to`` works in place: the caller's network, used elsewhere, would change)."""
    params = list(net.parameters())
    there = all(p.dtype == dtype and p.device == device for p in params)
    return (net if there else copy.deepcopy(net).to(device, dtype)).eval()


__all__ = [
    "DTYPES",
    "MAX_CHUNK",
    "Checked",
    "Fixed",
    "check_chunk",
    "check_chunk_size",
    "check_device",
    "check_dtype",
    "check_flag",
    "placed",
]
