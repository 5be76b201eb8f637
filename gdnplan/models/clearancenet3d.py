"""A ClearanceNet-style MLP baseline for the 3-D box scenes (issue #24, Table I style).

As ClearanceNet (:mod:`gdnplan.models.clearancenet`): an MLP regresses the signed distance from
the joint angles and a fixed-size obstacle vector, the pose of every obstacle in generation
order — for ``ur5e_boxes`` the centre and full sides (m) of each of the N_BOXES boxes:

    d̂(q, O) = scale · MLP([q / π, c_1, s_1, …, c_M, s_M]),    ∂d̂/∂q by autograd.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np
import torch
from torch import nn

from ..arm3d import Scene3D
from ..errors import InputError
from ..scene import check_scene


@dataclass(frozen=True)
class ClearanceNet3DConfig:
    """dof, boxes M, hidden widths, output scale (m)."""

    dof: int = 6
    n_boxes: int = 20
    hidden: tuple[int, ...] = (256, 256, 256)
    scale: float = 1.0

    def to_dict(self) -> dict:
        return asdict(self)


class ClearanceNet3D(nn.Module):
    """The MLP of :class:`ClearanceNet3DConfig`; ``forward(q (B, dof), boxes (B, 6 M))``."""

    def __init__(self, config: ClearanceNet3DConfig):
        super().__init__()
        self.config = config
        sizes = [config.dof + 6 * config.n_boxes, *config.hidden, 1]
        layers: list[nn.Module] = []
        for i in range(len(sizes) - 1):
            layers.append(nn.Linear(sizes[i], sizes[i + 1]))
            if i < len(sizes) - 2:
                layers.append(nn.ReLU())
        self.mlp = nn.Sequential(*layers)

    def forward(self, q: torch.Tensor, boxes: torch.Tensor) -> torch.Tensor:
        return self.mlp(torch.cat([q / torch.pi, boxes], -1)).squeeze(-1) * self.config.scale


def box_vector(centers: np.ndarray, sizes: np.ndarray) -> np.ndarray:
    """(…, 6 M) obstacle vectors of box centres and sides (…, M, 3) (m)."""
    return np.concatenate([centers, sizes], -1).reshape(*centers.shape[:-2], -1)


def scene_vector(scene: Scene3D, n_boxes: int) -> np.ndarray:
    """(6 M,) obstacle vector of a scene of exactly ``n_boxes`` axis-aligned boxes."""
    if len(scene.obstacles) != n_boxes or not all(
        hasattr(o.shape, "halfSide") for o in scene.obstacles
    ):
        raise InputError(f"scene: ClearanceNet-3D takes exactly {n_boxes} boxes")
    centers = np.array([o.pose.getTranslation() for o in scene.obstacles])
    sizes = np.array([2 * np.asarray(o.shape.halfSide) for o in scene.obstacles])
    return box_vector(centers, sizes)


class ClearanceNet3DModel:
    """The MLP as a DistanceModel of box scenes (robot–obstacle distance, m; ∂d̂/∂q m/rad)."""

    name = "clearancenet3d"

    def __init__(self, net: ClearanceNet3D, dtype: torch.dtype = torch.float32):
        self.net = net.to(dtype).eval()
        self.dtype = dtype

    def _inputs(self, scene: Scene3D, q) -> tuple[torch.Tensor, torch.Tensor]:
        check_scene(scene, "3d", "a planar model (ClearanceNet)")
        q = torch.as_tensor(scene.robot.check_q(q), dtype=self.dtype)
        o = torch.as_tensor(scene_vector(scene, self.net.config.n_boxes), dtype=self.dtype)
        return q, o.expand(len(q), -1)

    def distance(self, scene: Scene3D, q) -> np.ndarray:
        q, o = self._inputs(scene, q)
        with torch.no_grad():
            return self.net(q, o).double().numpy()

    def distance_and_grad(self, scene: Scene3D, q) -> tuple[np.ndarray, np.ndarray]:
        q, o = self._inputs(scene, q)
        q.requires_grad_(True)
        with torch.enable_grad():
            d = self.net(q, o)
            (g,) = torch.autograd.grad(d.sum(), q)
        return d.detach().double().numpy(), g.double().numpy()
