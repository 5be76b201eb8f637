"""GraphDistNet-3D (issue #24): the planner-safe GraphDistNet on 3-D robot and obstacle graphs.

* :mod:`.config`: :class:`GraphDistNet3DConfig`;
* :mod:`.network`: :class:`GraphDistNet3D` (obstacle pass once per scene, robot pass per q);
* :mod:`.model`: :class:`GraphDistNet3DModel`, the DistanceModel of 3-D scenes (∂d̂/∂q through
  the node Jacobians, exact self-collision beside the learned robot–obstacle distance);
* :mod:`.load`: weights files (safetensors + JSON card), a network started from one.
"""

from .config import GraphDistNet3DConfig
from .load import init_from_weights, load_graphdistnet3d, read_graphdistnet3d
from .model import (
    GraphDistNet3DModel,
    boxes_input,
    forward_with_grad,
    obstacle_input,
    robot_tensors,
)
from .network import GraphDistNet3D, ObstacleFeatures, ObstacleInput

__all__ = [
    "GraphDistNet3D",
    "GraphDistNet3DConfig",
    "GraphDistNet3DModel",
    "ObstacleFeatures",
    "ObstacleInput",
    "boxes_input",
    "forward_with_grad",
    "init_from_weights",
    "load_graphdistnet3d",
    "obstacle_input",
    "read_graphdistnet3d",
    "robot_tensors",
]
