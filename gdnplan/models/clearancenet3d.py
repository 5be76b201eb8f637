"""A ClearanceNet-style MLP baseline for the 3-D box scenes (issue #24, Table I style).

As ClearanceNet (:mod:`gdnplan.models.clearancenet`): an MLP regresses the signed distance from
the joint angles and a fixed-size obstacle vector, the pose of every obstacle in generation
order — for ``ur5e_boxes`` the centre and full sides (m) of each of the N_BOXES boxes:

    d̂(q, O) = scale · MLP([q / π, c_1, s_1, …, c_M, s_M]),    ∂d̂/∂q by autograd.

The sides are the box's extents along the world axes: a box turned by a multiple of 90° gives
its permuted sides; any other rotation has no input and is refused. The robot is not an input
at all: the MLP knows only the arm it was trained on (:data:`TRAINED`, the UR5e among the
random boxes of ``ur5e_boxes``; :func:`gdnplan.train.clearancenet3d.load_arrays`), so
:meth:`ClearanceNet3DModel.check_scene` refuses another robot (the UR5 has six joints too and
got the UR5e's distances), another joint count (torch's "mat1 and mat2 shapes cannot be
multiplied") and obstacles outside that training
(:func:`gdnplan.models.graphdistnet3d.fit.check_fits3d`).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np
import torch
from torch import nn

from ..arm3d import Scene3D
from ..errors import InputError
from ..scene import check_scene
from .outputs import finite
from .settings import Fixed, check_dtype

TRAINED = {"robot": "ur5e", "env": "ur5e_boxes"}  # the scenes ClearanceNet-3D is trained on


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
    """(6 M,) obstacle vector of a scene of exactly ``n_boxes`` axis-aligned boxes: centres and
    extents along the world axes (m); InputError for another count, shape or a rotation that
    is not a multiple of 90° about the axes."""
    if len(scene.obstacles) != n_boxes or not all(
        hasattr(o.shape, "halfSide") for o in scene.obstacles
    ):
        raise InputError(f"scene: ClearanceNet-3D takes exactly {n_boxes} boxes")
    centers = np.array([o.pose.getTranslation() for o in scene.obstacles])
    turns = np.abs(np.array([o.pose.getRotation() for o in scene.obstacles]))  # (M, 3, 3)
    tilted = [
        i for i, r in enumerate(turns) if not np.allclose(np.sort(r, 1), [0, 0, 1], atol=1e-6)
    ]
    if tilted:
        raise InputError(
            f"scene.obstacles[{tilted[0]}] ({scene.obstacles[tilted[0]].name!r}): ClearanceNet-3D "
            "takes axis-aligned boxes (its input has no rotation); use collision='coal'"
        )
    sides = np.array([2 * np.asarray(o.shape.halfSide) for o in scene.obstacles])
    return box_vector(centers, np.einsum("mij,mj->mi", turns, sides))


class ClearanceNet3DModel:
    """The MLP as a DistanceModel of box scenes (robot–obstacle distance, m; ∂d̂/∂q m/rad)."""

    name = "clearancenet3d"
    dtype = Fixed()  # the network is placed in it (models/settings.py)

    def __init__(self, net: ClearanceNet3D, dtype: torch.dtype = torch.float32):
        self.dtype = check_dtype(dtype)
        self.net = net.to(dtype).eval()
        self._fits: Scene3D | None = None  # the last scene check_scene accepted

    def check_scene(self, scene: Scene3D) -> None:
        """InputError unless ``scene`` is one the MLP takes (module docstring): a 3-D scene of
        the trained robot (:data:`TRAINED`) with the net's joint count, and exactly
        ``n_boxes`` boxes of the training distribution."""
        check_scene(scene, "3d", "a planar model (ClearanceNet)")
        if scene is self._fits:
            return
        from .graphdistnet3d.fit import check_fits3d

        dof, robot = self.net.config.dof, scene.robot
        if robot.dof != dof:
            raise InputError(
                f"scene.robot: this ClearanceNet-3D takes {dof} joint angles, robot "
                f"{robot.name!r} has {robot.dof}; use collision='coal'"
            )
        check_fits3d(TRAINED, 8, scene)
        scene_vector(scene, self.net.config.n_boxes)
        self._fits = scene

    def _inputs(self, scene: Scene3D, q) -> tuple[torch.Tensor, torch.Tensor]:
        self.check_scene(scene)
        q = torch.as_tensor(scene.robot.check_q(q), dtype=self.dtype)
        o = torch.as_tensor(scene_vector(scene, self.net.config.n_boxes), dtype=self.dtype)
        return q, o.expand(len(q), -1)

    def distance(self, scene: Scene3D, q) -> np.ndarray:
        q, o = self._inputs(scene, q)
        with torch.no_grad():
            d = self.net(q, o).double().numpy()
        finite(self, d)
        return d

    def distance_and_grad(self, scene: Scene3D, q) -> tuple[np.ndarray, np.ndarray]:
        q, o = self._inputs(scene, q)
        q.requires_grad_(True)
        with torch.enable_grad():
            d = self.net(q, o)
            (g,) = torch.autograd.grad(d.sum(), q)
        out = d.detach().double().numpy(), g.double().numpy()
        finite(self, *out)
        return out
