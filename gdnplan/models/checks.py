"""Checks of weights files: readable tensors and card, tensors that fit the card's network, and
weights that fit the scene they are used on. Every failure is an InputError naming the file and
the fix.

What "fit the scene" means (:func:`check_fits`):

* the kind of scene: planar weights refuse a 3-D scene (:class:`~gdnplan.arm3d.Scene3D`;
  the UR5e's planar weights would otherwise accept the 3-D UR5e by name);
* the robot: a card names the robot its network was trained for (``"robot"``, else the robot
  of its ``"env"``; ClearanceNet's config also fixes the joint count ``dof``). Another robot is
  an error: GraphDistNet's graph input accepts any robot, but its estimates for a robot it never
  saw are meaningless (docs/decisions.md, "Training and models"). The robot's node count is not
  compared: the fetch robot's graph grows with the gripper's stick, and the ur5e weights are
  trained on those variants.
* the obstacle layout: GraphDistNet reads the obstacles as a graph, so weights trained on one
  layout are used on others of the same robot; that is what the weights of the random
  environments (b), (d), (e) are for, and the shipped weights of a fixed layout stay usable on
  the random layouts of their robot. ClearanceNet, by contrast, takes a fixed-size vector of
  obstacle poses: trained on a fixed layout ((a), (c)) it never saw that vector change, and it
  rates most colliding configurations of other layouts free. ClearanceNet weights of a fixed
  layout therefore only accept that layout, and its pose encoding only squares (4-vertex
  obstacles). The measurements behind both rules: docs/decisions.md.
"""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path

import numpy as np
import torch
from safetensors.torch import load_file

from ..arm3d.scene3d import Scene3D
from ..errors import InputError
from ..files import read_input
from ..scene import ENV_ROBOT, Scene
from .outputs import RETRAIN, check_magnitudes

FIXED_LAYOUT_ENVS = ("a", "c")  # environments whose obstacles never change (scene.py)


def parse_card(card: Path, what: str = "weights") -> dict:
    """The JSON object in the card file ``card``; InputError when it is unreadable or not one."""
    try:
        content = json.loads(read_input(card, f"{what}: card").decode("utf-8"))
    except InputError:
        raise
    except (UnicodeDecodeError, ValueError, RecursionError) as e:
        raise InputError(f"{what}: card {card} is not valid JSON ({e}); {RETRAIN}") from e
    if not isinstance(content, dict):
        raise InputError(
            f"{what}: card {card} must be a JSON object, got {type(content).__name__}; {RETRAIN}"
        )
    return content


def load_tensors(path: Path, what: str = "weights") -> dict[str, torch.Tensor]:
    """The tensors of the safetensors file ``path``, all finite; InputError otherwise."""
    try:
        tensors = load_file(str(path))
    except Exception as e:  # safetensors raises its own error types, OSError for directories
        why = " ".join(str(e).split())[:200]
        raise InputError(
            f"{what}: {path} is not a safetensors file ({type(e).__name__}: {why}); it may be "
            f"truncated, a pickle or torch.save file; {RETRAIN}"
        ) from e
    for name, t in tensors.items():
        if not (t.is_floating_point() or t.is_complex()):
            continue
        if not bool(torch.isfinite(t).all()):
            raise InputError(
                f"{what}: {path} tensor {name!r} has NaN or infinite values; {RETRAIN}"
            )
    return tensors


def card_config(path: Path, card: dict, kind: str, make: Callable[[dict], object]):
    """``make(card["config"])``, any failure an InputError naming the card of ``path``."""
    config = card.get("config")
    if not isinstance(config, dict):
        raise InputError(
            f"weights: card {path.with_suffix('.json').name} has no {kind} 'config' object; "
            f"{RETRAIN}"
        )
    try:
        return make(config)
    except InputError as e:
        raise InputError(f"weights: card {path.with_suffix('.json').name}: {e}") from e
    except (TypeError, ValueError, KeyError, OverflowError) as e:
        raise InputError(
            f"weights: card {path.with_suffix('.json').name} has an invalid {kind} config "
            f"({type(e).__name__}: {e}); {RETRAIN}"
        ) from e


def build_net(
    path: Path, kind: str, make: Callable[[], torch.nn.Module], tensors: dict[str, torch.Tensor]
) -> torch.nn.Module:
    """The network ``make()`` holding ``tensors``; InputError when they do not fit it (a
    missing or unexpected name, another shape, an int, bool or complex tensor, a value beyond
    :data:`.outputs.MAX_WEIGHT`).

    The network is first built on the meta device (no memory), so a card asking for a huge
    network costs nothing before its shapes are compared with the file's tensors.
    """
    card = path.with_suffix(".json").name
    try:
        with torch.device("meta"):
            meta = make().state_dict()
        expected = {k: tuple(v.shape) for k, v in meta.items()}
    except (TypeError, ValueError, RuntimeError, OverflowError) as e:
        raise InputError(
            f"weights: card {card} has an invalid {kind} config ({type(e).__name__}: {e}); "
            + RETRAIN
        ) from e
    got = {k: tuple(v.shape) for k, v in tensors.items()}
    missing, unexpected = sorted(expected.keys() - got), sorted(got.keys() - expected)
    shapes = [
        f"{k} {got[k]} ≠ {expected[k]}" for k in expected.keys() & got if got[k] != expected[k]
    ]
    if missing or unexpected or shapes:
        parts = [
            f"{label} {items[:3]}{' …' if len(items) > 3 else ''}"
            for label, items in (
                ("missing", missing),
                ("unexpected", unexpected),
                ("shapes", shapes),
            )
            if items
        ]
        raise InputError(
            f"weights: the tensors of {path.name} do not fit the {kind} network of its card "
            f"{card} ({'; '.join(parts)}); the card belongs to other weights, or the file to "
            "another model: keep each .safetensors with its own .json"
        )
    _check_dtypes(path, {k: v.dtype for k, v in meta.items()}, tensors)
    check_magnitudes(path, tensors)
    net = make()
    net.load_state_dict(tensors)
    return net


def _check_dtypes(path: Path, expected: dict, tensors: dict[str, torch.Tensor]) -> None:
    """InputError naming the first tensor that is no real float (int, bool, complex) where the
    network holds one: ``load_state_dict`` would cast it silently (an int tensor truncates
    every weight, a complex one drops its imaginary part, a bool one makes every weight 0 or
    1). Any float width is kept (float16/bfloat16/float64 files load as float32)."""
    for name, dtype in expected.items():
        got = tensors[name].dtype
        if dtype.is_floating_point and not got.is_floating_point:
            raise InputError(
                f"weights: {path.name} tensor {name!r} holds {str(got).removeprefix('torch.')} "
                f"values, the network real numbers (float32); the file was not written by "
                f"gdnplan's training: {RETRAIN}"
            )


def check_count(value: object, limit: int, name: str, path: Path) -> None:
    """InputError unless ``value`` is an int in 1 … ``limit`` (sizes read from a card)."""
    if isinstance(value, bool) or not isinstance(value, int) or not 1 <= value <= limit:
        raise InputError(
            f"weights: card {path.with_suffix('.json').name} config {name}: expected an "
            f"integer in 1 … {limit} (what its tensors allow), got {value!r}"
        )


def check_depths(config: object, tensors: dict, path: Path) -> None:
    """InputError unless a graph network's card asks for no more layers, edge-MLP layers and
    readout layers than its tensors hold (checked before the network is built: a card asking
    for a huge network would otherwise allocate it first)."""
    limit = len(tensors)
    check_count(config.layers, limit, "layers", path)
    check_count(len(config.mlp) or 1, limit, "mlp", path)
    check_count(len(config.readout) or 1, limit, "readout", path)


def card_robot(card: dict) -> str | None:
    """The robot the card's weights were trained for (None: the card does not say)."""
    robot = card.get("robot")
    if isinstance(robot, str):
        return robot
    env = card.get("env")
    return "ur5e" if env == "ur5e" else ENV_ROBOT.get(env) if isinstance(env, str) else None


def check_fits(card: dict, scene: Scene, dof: int | None = None) -> None:
    """InputError unless the weights of ``card`` were trained for ``scene``'s robot (and
    ``dof`` joints, when the network fixes it); see the module docstring."""
    robot, env = card_robot(card), card.get("env")
    have = scene.robot
    source = f"{card.get('model', 'model')} weights of environment {env!r}"
    if isinstance(scene, Scene3D):
        raise InputError(
            f"weights: {source} are planar and this is a 3-D scene ({have.name}, {have.dof} "
            "joints); use GraphDistNet-3D weights (a card of model graphdistnet3d, e.g. "
            "'ur5e_boxes3d_preliminary') or collision='coal'"
        )
    if robot is not None and robot != have.name:
        raise InputError(
            f"weights: {source} were trained for the {robot} robot, but the scene's robot is "
            f"{have.name} ({have.dof} joints); use weights trained for {have.name} "
            "(weights=..., --weights) or collision='coal'"
        )
    if dof is not None and dof != have.dof:
        raise InputError(
            f"weights: {source} take {dof} joints, but the scene's robot {have.name} has "
            f"{have.dof}; use weights trained for this robot"
        )


def check_layout(card: dict, scene: Scene, reference: Callable[[], Scene]) -> None:
    """InputError unless ``scene`` has the obstacles of the card's fixed-layout environment
    (ClearanceNet, module docstring); ``reference()`` builds that environment's scene."""
    env = card.get("env")
    if env not in FIXED_LAYOUT_ENVS:
        return
    ref = reference().obstacles
    same = len(ref) == len(scene.obstacles) and all(
        a.shape == b.shape and np.allclose(a, b, atol=1e-9)
        for a, b in zip(ref, scene.obstacles, strict=True)
    )
    if not same:
        raise InputError(
            f"weights: ClearanceNet weights of environment {env!r} know only that "
            "environment's fixed obstacles, and this scene's obstacles differ; use ClearanceNet "
            "weights of a random environment (b, d, e), GraphDistNet or coal"
        )
