"""gdnplan: collision-free trajectory planning with GraphDistNet, a learned collision distance.

The names of ``__all__`` load on first use (PEP 562 module ``__getattr__``): ``import gdnplan``
costs the error classes only, so the command line's ``--help`` and coal-only planning never
import torch, and ``gdnplan.plan`` imports the planner (CasADi, pinocchio, coal) when first
touched. Submodules (``gdnplan.trajopt`` …) load on attribute access too. The library logs its
progress (planner stages, fetch stages) to the ``gdnplan`` logger at INFO; it prints nothing
unless a handler is attached (the command line attaches one to stderr, ``--quiet`` detaches it).
"""

from __future__ import annotations

import importlib
import importlib.util
import logging
from importlib.metadata import version
from typing import TYPE_CHECKING

from .errors import (
    GdnplanError,
    InfeasibleProblemError,
    InputError,
    OutputError,
    ProblemFileError,
    UnknownNameError,
)
from .registry import ROBOTS, SCENES

# The built-in robots and scenes defined outside robot.py and scene.py, by the module that
# registers each; imported on first lookup (gdnplan.registry), so the core never imports them.
ROBOTS.declare(
    {
        "planar2": "gdnplan.planar",
        "planar7": "gdnplan.planar",
        "ur5e": "gdnplan.ur5e.arms",
        "ur5": "gdnplan.ur5e.arms",
    }
)
SCENES.declare({"fetch": "gdnplan.ur5e.scene"})

if TYPE_CHECKING:  # what the lazy names are, for type checkers and IDEs
    from .casadi_bridge import DistanceCallback
    from .ccd import certify_path, verify_path
    from .distance import signed_distance, signed_distance_and_grad
    from .models import CoalModel, DistanceModel, load_model
    from .robot import Robot, load_robot, robot_names
    from .scene import Scene, make_scene, scene_names
    from .trajopt import (
        AdamConfig,
        IpoptConfig,
        Plan,
        PlanConfig,
        Problem,
        RefineConfig,
        SeedConfig,
        TrajoptOptions,
        plan,
    )
    from .urdf_robot import RobotSpec, robot_from_urdf

__version__ = version("gdnplan")
logging.getLogger(__name__).addHandler(logging.NullHandler())

_LAZY = {  # public name -> the submodule defining it
    "DistanceCallback": "casadi_bridge",
    "certify_path": "ccd",
    "verify_path": "ccd",
    "signed_distance": "distance",
    "signed_distance_and_grad": "distance",
    "CoalModel": "models",
    "DistanceModel": "models",
    "load_model": "models",
    "Robot": "robot",
    "load_robot": "robot",
    "robot_names": "robot",
    "Scene": "scene",
    "make_scene": "scene",
    "scene_names": "scene",
    "Plan": "trajopt",
    "Problem": "trajopt",
    "TrajoptOptions": "trajopt",
    "PlanConfig": "trajopt",
    "SeedConfig": "trajopt",
    "RefineConfig": "trajopt",
    "IpoptConfig": "trajopt",
    "AdamConfig": "trajopt",
    "plan": "trajopt",
    "RobotSpec": "urdf_robot",
    "robot_from_urdf": "urdf_robot",
}

__all__ = [
    "AdamConfig",
    "CoalModel",
    "DistanceCallback",
    "DistanceModel",
    "GdnplanError",
    "InfeasibleProblemError",
    "InputError",
    "IpoptConfig",
    "OutputError",
    "Plan",
    "PlanConfig",
    "Problem",
    "ProblemFileError",
    "RefineConfig",
    "Robot",
    "RobotSpec",
    "Scene",
    "SeedConfig",
    "TrajoptOptions",
    "UnknownNameError",
    "certify_path",
    "load_model",
    "load_robot",
    "make_scene",
    "plan",
    "robot_from_urdf",
    "robot_names",
    "scene_names",
    "signed_distance",
    "signed_distance_and_grad",
    "verify_path",
]


def __getattr__(name: str) -> object:
    """A public name of ``__all__`` or a submodule, imported on first access and cached."""
    if name in _LAZY:
        value = getattr(importlib.import_module(f".{_LAZY[name]}", __name__), name)
    elif not name.startswith("__") and importlib.util.find_spec(f"{__name__}.{name}"):
        value = importlib.import_module(f".{name}", __name__)
    else:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))
