"""gdnplan: collision-free trajectory planning with GraphDistNet, a learned collision distance."""

from . import ur5e  # noqa: F401  (registers the ur5e and ur5 robots and the fetch scene)
from .distance import signed_distance, signed_distance_and_grad
from .errors import (
    GdnplanError,
    InfeasibleProblemError,
    InputError,
    ProblemFileError,
    UnknownNameError,
)
from .models import CoalModel, DistanceModel, load_model
from .robot import Robot, load_robot, robot_names
from .scene import Scene, make_scene, scene_names

__all__ = [
    "CoalModel",
    "DistanceModel",
    "GdnplanError",
    "InfeasibleProblemError",
    "InputError",
    "ProblemFileError",
    "Robot",
    "Scene",
    "UnknownNameError",
    "load_model",
    "load_robot",
    "make_scene",
    "robot_names",
    "scene_names",
    "signed_distance",
    "signed_distance_and_grad",
]
