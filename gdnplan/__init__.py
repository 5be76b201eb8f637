"""gdnplan: collision-free trajectory planning with GraphDistNet, a learned collision distance."""

from importlib.metadata import version as _version

from . import ur5e  # noqa: F401  (registers the ur5e and ur5 robots and the fetch scene)
from .casadi_bridge import DistanceCallback
from .ccd import certify_path, verify_path
from .distance import signed_distance, signed_distance_and_grad
from .errors import (
    GdnplanError,
    InfeasibleProblemError,
    InputError,
    OutputError,
    ProblemFileError,
    UnknownNameError,
)
from .models import CoalModel, DistanceModel, load_model
from .robot import Robot, load_robot, robot_names
from .scene import Scene, make_scene, scene_names
from .trajopt import Plan, Problem, TrajoptOptions, plan
from .urdf_robot import RobotSpec, robot_from_urdf

__version__ = _version("gdnplan")

__all__ = [
    "CoalModel",
    "DistanceCallback",
    "DistanceModel",
    "GdnplanError",
    "InfeasibleProblemError",
    "InputError",
    "OutputError",
    "Plan",
    "Problem",
    "ProblemFileError",
    "Robot",
    "RobotSpec",
    "Scene",
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
