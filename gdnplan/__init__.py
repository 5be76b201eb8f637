"""gdnplan: collision-free trajectory planning with GraphDistNet, a learned collision distance."""

from .errors import GdnplanError, InfeasibleProblemError, InputError, ProblemFileError, UnknownNameError
from .robot import Robot, load_robot, robot_names

__all__ = [
    "GdnplanError",
    "InfeasibleProblemError",
    "InputError",
    "ProblemFileError",
    "Robot",
    "UnknownNameError",
    "load_robot",
    "robot_names",
]
