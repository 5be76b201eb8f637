"""Finite outputs of the learned models, and weights small enough to give them.

A weights file passes :func:`gdnplan.models.checks.load_tensors` when every value is finite,
but finite values can still overflow the network's float32 arithmetic: every tensor × 1e30, or
one entry of 3e38, loads and gives NaN or ±inf distances (or a ZeroDivisionError inside the
compiled pass's soft minimum). Two checks keep such numbers from a planner:

- at load, :func:`check_magnitudes`: every network tensor within ±:data:`MAX_WEIGHT`. Trained
  weights are far below it (the shipped ones below 50); a larger value is a damaged or
  hand-edited file, refused naming the tensor;
- at every public distance and gradient (:func:`finite`, :func:`overflow_guard`): d̂ (B,) and
  ∂d̂/∂q (B, dof) all finite, else InputError naming the model's weights file and the first
  configuration. Weights within the bound can still overflow somewhere (a wide layer of large
  weights); this check is the guarantee, the bound only the earlier, clearer error.
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import numpy as np
import torch

from ..errors import InputError

MAX_WEIGHT = 1e6  # largest |value| of a network tensor in a weights file (module docstring)
RETRAIN = "re-download the shipped weights or train them again (gdnplan train)"


def check_magnitudes(path: Path, tensors: dict[str, torch.Tensor]) -> None:
    """InputError naming the first floating tensor of ``tensors`` (the weights file ``path``)
    holding a value beyond ±:data:`MAX_WEIGHT`."""
    for name, t in tensors.items():
        if not t.is_floating_point() or t.numel() == 0:
            continue
        largest = float(t.detach().abs().max())
        if largest > MAX_WEIGHT:
            raise InputError(
                f"weights: {path.name} tensor {name!r} holds a value of magnitude "
                f"{largest:.3g}, beyond {MAX_WEIGHT:g} (trained weights stay far below it; the "
                f"network's float32 arithmetic overflows to NaN or inf); the file is damaged "
                f"or edited: {RETRAIN}"
            )


def source(model: object) -> str:
    """How messages name ``model``: its weights file when it was loaded from one (``source``),
    else its card's name, else its class."""
    where = getattr(model, "source", None)
    if where:
        return f"weights {where}"
    card = getattr(model, "card", None) or {}
    name = card.get("name") if isinstance(card, dict) else None
    kind = getattr(model, "name", type(model).__name__)
    return f"{kind} weights {name!r}" if isinstance(name, str) else f"the {kind} network"


def _refuse(model: object, count: int, total: int, first: int, what: str) -> InputError:
    return InputError(
        f"weights: {source(model)} gave {what} for {count} of {total} configurations (the "
        f"first: q[{first}]); the network's weights overflow its arithmetic (a damaged or "
        f"edited file, or a diverged training run): {RETRAIN}"
    )


def finite(model: object, d: np.ndarray, g: np.ndarray | None = None) -> None:
    """InputError unless the distances ``d`` (B,) and gradients ``g`` (B, dof) of ``model``
    are all finite (the message names its weights and the first bad configuration)."""
    bad = ~np.isfinite(d)
    what = "NaN or infinite distances"
    if g is not None:
        bad_g = ~np.isfinite(g).reshape(len(g), -1).all(axis=1) if len(g) else bad
        if bad_g.any() and not bad.any():
            what = "NaN or infinite gradients"
        bad = bad | bad_g
    if bad.any():
        raise _refuse(model, int(bad.sum()), len(bad), int(np.argmax(bad)), what)


@contextmanager
def overflow_guard(model: object) -> Iterator[None]:
    """Run the block; a ZeroDivisionError, FloatingPointError or OverflowError in it (the
    compiled passes' arithmetic on overflowed values) becomes the InputError of
    :func:`finite`, naming ``model``'s weights."""
    try:
        yield
    except (ZeroDivisionError, FloatingPointError, OverflowError) as e:
        raise InputError(
            f"weights: {source(model)} overflowed its arithmetic ({type(e).__name__}: {e}) "
            f"inside the network (a damaged or edited file, or a diverged training run): "
            f"{RETRAIN}"
        ) from e
