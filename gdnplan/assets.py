"""Shipped files — robot URDFs, example problems, trained weights — and how to name them.

Everything gdnplan ships lives in the package (``gdnplan/shipped/``) and is found with
:mod:`importlib.resources`, so an installed wheel works from any directory. The repository's
top-level ``robots/``, ``problems/`` and ``weights/`` are links into that folder (one copy of
each file in git).

A shipped file is named by its stem: ``"fetch_reach"`` is ``shipped/problems/fetch_reach.toml``,
``"d"`` is ``shipped/weights/d.safetensors`` with its card ``d.json``. Anything that looks like
a path (a separator or a suffix) is taken as a path instead, so user files keep working.

Which learned weights a scene gets by default depends on its robot and the kind of its
obstacles, never on the scene's name (see :func:`default_weights`).
"""

from __future__ import annotations

from importlib import resources
from pathlib import Path
from typing import TYPE_CHECKING

from .errors import InputError, UnknownNameError, did_you_mean

if TYPE_CHECKING:
    from .scene import Scene

SHIPPED = Path(str(resources.files("gdnplan") / "shipped"))
ROBOTS_DIR = SHIPPED / "robots"
PROBLEMS_DIR = SHIPPED / "problems"
WEIGHTS_DIR = SHIPPED / "weights"
WEIGHTS_SUFFIX = ".safetensors"


def _names(folder: Path, suffix: str) -> list[str]:
    return sorted(p.name.removesuffix(suffix) for p in folder.glob(f"*{suffix}"))


def problem_names() -> list[str]:
    """Names of the shipped example problems (``gdnplan plan <name>``)."""
    return _names(PROBLEMS_DIR, ".toml")


def weights_names() -> list[str]:
    """Names of the shipped trained weights (``load_model(<name>)``, ``--weights <name>``)."""
    return _names(WEIGHTS_DIR, WEIGHTS_SUFFIX)


def looks_like_path(ref: str | Path) -> bool:
    """True when ``ref`` is a path rather than a shipped name: a Path, or a string with a
    directory separator or a file suffix (``"d"`` is a name, ``"d.safetensors"`` a path)."""
    if isinstance(ref, Path):
        return True
    return "/" in ref or "\\" in ref or Path(ref).suffix != "" or ref in (".", "..")


def _check_ref(ref, what: str) -> None:
    """InputError unless ``ref`` is a name (str) or a path (pathlib.Path)."""
    if not isinstance(ref, (str, Path)):
        raise InputError(
            f"{what}: expected a shipped {what} name or a file path, got {type(ref).__name__}"
        )


def is_file(path: Path | str, what: str, ref: object = None) -> bool:
    """``Path(path).is_file()``, with any OSError while looking (a name longer than the file
    system allows, a folder without permission) an InputError naming the argument ``what``
    and the reference ``ref`` it came from (default: ``path``), cut to one short line."""
    try:
        return Path(path).is_file()
    except OSError as e:
        text = str(path if ref is None else ref)
        cut = text if len(text) <= 60 else f"{text[:60]}… ({len(text)} characters)"
        raise InputError(
            f"{what}: cannot look up {cut!r} ({e.strerror or type(e).__name__}); give a shipped "
            f"{what} name or the path of an existing file"
        ) from e


def _shipped(ref: str, folder: Path, suffix: str, what: str, names: list[str]) -> Path:
    path = folder / f"{ref}{suffix}"
    if not is_file(path, what, ref):
        raise UnknownNameError(
            f"{what}: no shipped {what} named {ref!r}{did_you_mean(ref, names)}; choose one of "
            f"{names} or give a path"
        )
    return path


def problem_file(ref: str | Path) -> Path:
    """The problem file ``ref`` names: a path as given (or an existing file), or a shipped
    problem by name (``"fetch_reach"``; see :func:`problem_names`)."""
    _check_ref(ref, "problem")
    if looks_like_path(ref) or is_file(ref, "problem"):
        return Path(ref)
    return _shipped(str(ref), PROBLEMS_DIR, ".toml", "problem", problem_names())


def weights_file(ref: str | Path) -> Path:
    """The weights file ``ref`` names: a path as given, or shipped weights by name."""
    _check_ref(ref, "weights")
    if looks_like_path(ref) and Path(ref).suffix == ".json":  # else "card … does not belong"
        raise InputError(
            f"weights: {ref} is a card; give the weights file beside it, "
            f"{Path(ref).with_suffix(WEIGHTS_SUFFIX)}"
        )
    if looks_like_path(ref):
        return Path(ref)
    return _shipped(str(ref), WEIGHTS_DIR, WEIGHTS_SUFFIX, "weights", weights_names())


def robot_urdf(name: str) -> Path:
    """The shipped URDF of robot ``name`` (``planar2``, ``planar7``, ``ur5e``)."""
    return ROBOTS_DIR / f"{name}.urdf"


# Learned weights for each robot: its fixed-layout scenes first, then its general default.
FIXED_LAYOUT_WEIGHTS = {"planar2": ("a",), "planar7": ("c",)}
ROBOT_WEIGHTS = {"planar2": "b", "planar7": "d", "ur5e": "ur5e"}
NON_CONVEX_WEIGHTS = {"planar7": "e"}  # trained on α-shapes


def default_weights(scene: Scene) -> str:
    """Name of the shipped GraphDistNet weights for ``scene``, chosen by robot and obstacles.

    - The exact obstacle layout of a fixed environment (a, c): that environment's weights.
    - planar7 with any non-convex obstacle: ``e`` (trained on random α-shapes).
    - Otherwise the robot's general weights: planar2 → ``b`` (one random square), planar7 →
      ``d`` (20 random squares), ur5e → ``ur5e`` (the fetch storage and random boxes).

    Raises UnknownNameError for a robot without shipped weights (train your own with
    ``gdnplan train`` and pass its path).
    """
    from .scene import make_scene  # scene builds robots; assets stays importable without it

    robot = scene.robot.name
    if robot not in ROBOT_WEIGHTS:
        raise UnknownNameError(
            f"weights: no shipped GraphDistNet weights for robot {robot!r} (shipped: "
            f"{sorted(ROBOT_WEIGHTS)}); train them with `gdnplan train` and pass weights=<path>"
        )
    for env in FIXED_LAYOUT_WEIGHTS.get(robot, ()):
        if same_obstacles(scene, make_scene(env)):
            return env
    if robot in NON_CONVEX_WEIGHTS and len(scene.obstacle_parts) > len(scene.obstacles):
        return NON_CONVEX_WEIGHTS[robot]
    return ROBOT_WEIGHTS[robot]


def same_obstacles(a: Scene, b: Scene, tol: float = 1e-9) -> bool:
    """True when scenes ``a`` and ``b`` hold the same obstacle polygons (vertices within tol m)."""
    if len(a.obstacles) != len(b.obstacles):
        return False
    return all(
        p.shape == r.shape and bool(abs(p - r).max() <= tol)
        for p, r in zip(a.obstacles, b.obstacles, strict=True)
    )
