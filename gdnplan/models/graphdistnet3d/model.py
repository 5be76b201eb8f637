"""GraphDistNet-3D as a :class:`~gdnplan.models.DistanceModel` of 3-D scenes (the interface of
:class:`~gdnplan.arm3d.Coal3DModel`), and its inputs from graphs.

q → node positions and WORLD joint Jacobian columns (:meth:`RobotGraph3D.kinematics`, Pinocchio,
float64) → d̂ of the robot–obstacle distance (``dtype``, chunks of ``chunk`` configurations) →
∂d̂/∂p_n by autograd on the node coordinates → ∂d̂/∂q = Σ_n (∂p_n/∂q)ᵀ ∂d̂/∂p_n
(:meth:`RobotGraph3D.pullback`). The obstacle features are computed once per scene object
(one-way cross edges) and cached. ``fused`` (default None: wherever it serves) runs the robot
pass — d̂ and ∂d̂/∂p in one call per batch, no chunks — as the compiled numba pass of
:mod:`.fused3d` instead of torch (False: torch; True: InputError where it cannot serve).
Self-collision stays exact (``self_collision=True``): the reported distance is min(d̂, d_self)
with d_self coal's signed distance over the robot's enabled self pairs
(:class:`~gdnplan.arm3d.Checker3D` of the robot alone), and the gradient is the minimiser's.
Contact-only self pairs (:mod:`gdnplan.arm3d.pairs`) enter d_self as d_k + o with o =
``contact_offset`` (m), as in :class:`~gdnplan.arm3d.Coal3DModel`: 0 (default) gives true signed
distances; the planner passes its margin M (:meth:`GraphDistNet3DModel.with_contact_offset`), so
that its rows d ≥ M also hold those pairs at d ≥ 0.
"""

from __future__ import annotations

import copy
import weakref
from dataclasses import dataclass

import numpy as np
import torch

from ...arm3d import Checker3D, Scene3D
from ...arm3d.narrow3d import check_offset
from ...errors import InputError
from ...graph3d import (
    ObstacleGraph3D,
    RobotGraph3D,
    box_graphs,
    robot_graph3d,
    scene_graph3d,
)
from ...scene import check_scene
from ..outputs import finite, overflow_guard
from ..settings import Checked, Fixed, check_chunk_size, check_dtype, check_flag, placed
from ..threads import check_threads, torch_threads
from . import fused3d
from .fit import check_fits3d
from .network import GraphDistNet3D, ObstacleFeatures, ObstacleInput

CHUNK = 256  # configurations per inference pass of the torch path
_NUMPY = {torch.float32: np.float32, torch.float64: np.float64}


def obstacle_input(
    graphs: list[ObstacleGraph3D], dtype: torch.dtype = torch.float32
) -> ObstacleInput:
    """Obstacle graphs of S scenes padded into one :class:`ObstacleInput` (S, N_o)."""
    n = max(g.n_nodes for g in graphs)
    e = max(g.nbr.shape[1] for g in graphs)
    s = len(graphs)
    nodes = np.zeros((s, n, 3))
    mask = np.zeros((s, n), bool)
    nbr = np.broadcast_to(np.arange(n)[None, :, None], (s, n, e)).copy()
    nbr_mask = np.zeros((s, n, e), bool)
    for i, g in enumerate(graphs):
        k, d = g.n_nodes, g.nbr.shape[1]
        nodes[i, :k], mask[i, :k] = g.nodes, True
        nbr[i, :k, :d], nbr_mask[i, :k, :d] = g.nbr, g.nbr_mask
    return ObstacleInput(
        torch.as_tensor(nodes, dtype=dtype),
        torch.as_tensor(mask),
        torch.as_tensor(nbr),
        torch.as_tensor(nbr_mask),
    )


def boxes_input(
    centers: np.ndarray, sizes: np.ndarray, dtype: torch.dtype = torch.float32
) -> ObstacleInput:
    """The graphs of S scenes of M axis-aligned boxes, centres and full sides (S, M, 3) (m):
    :func:`gdnplan.graph3d.box_graphs` of every scene, stacked (no padding: same structure)."""
    s, m, _ = centers.shape
    one = box_graphs(np.zeros((m, 3)), np.ones((m, 3)))  # the structure; unit corners ±0.5
    corners = one.nodes.reshape(m, 8, 3)
    nodes = (centers[:, :, None] + corners[None] * sizes[:, :, None]).reshape(s, m * 8, 3)
    return ObstacleInput(
        torch.as_tensor(nodes, dtype=dtype),
        torch.ones(s, m * 8, dtype=torch.bool),
        torch.as_tensor(one.nbr)[None].expand(s, -1, -1),
        torch.as_tensor(one.nbr_mask)[None].expand(s, -1, -1),
    )


def robot_tensors(graph: RobotGraph3D) -> tuple[torch.Tensor, torch.Tensor]:
    """The robot graph's neighbourhoods (N_r, E) as torch tensors (long, bool)."""
    return torch.as_tensor(graph.nbr), torch.as_tensor(graph.nbr_mask)


def forward_with_grad(
    net: GraphDistNet3D,
    graph: RobotGraph3D,
    nodes: torch.Tensor,
    jac: torch.Tensor,
    feats: ObstacleFeatures,
    create_graph: bool,
) -> tuple[torch.Tensor, torch.Tensor]:
    """d̂ (B,) and ∂d̂/∂q (B, dof) = Σ_n ∂d̂/∂p_n · J_n, J (B, N_r, 3, dof) (training)."""
    nbr, nbr_mask = robot_tensors(graph)
    x = nodes.detach().requires_grad_(True)
    with torch.enable_grad():
        d = net(x, nbr, nbr_mask, feats)
        (dx,) = torch.autograd.grad(d.sum(), x, create_graph=create_graph)
    return d, torch.einsum("bni,bnij->bj", dx, jac)


@dataclass(frozen=True)
class _SceneCache:
    graph: RobotGraph3D
    nbr: torch.Tensor
    nbr_mask: torch.Tensor
    feats: ObstacleFeatures
    self_checker: Checker3D | None
    packed: fused3d.Packed | None  # the compiled pass's arrays (None: torch)


class GraphDistNet3DModel:
    """A trained GraphDistNet-3D as a DistanceModel of :class:`~gdnplan.arm3d.Scene3D` s."""

    name = "graphdistnet3d"
    threads = Checked(check_threads)  # settable later, checked as here (models/settings.py)
    chunk = Checked(check_chunk_size)
    contact_offset = Checked(check_offset)
    dtype = Fixed()

    def __init__(
        self,
        net: GraphDistNet3D,
        card: dict | None = None,
        self_collision: bool = True,
        chunk: int = CHUNK,
        dtype: torch.dtype = torch.float32,
        threads: int | None = None,
        fused: bool | None = None,
        contact_offset: float = 0.0,
    ):
        self.dtype = check_dtype(dtype)
        self.net = placed(net, torch.device("cpu"), self.dtype)
        self.contact_offset = contact_offset
        self.config = net.config
        self.card = card or {}
        self.source: str | None = None  # the weights file it was loaded from (messages)
        self.chunk, self.threads = chunk, threads
        self._fused = self._check_fused(check_flag(fused, "fused", optional=True))
        self.self_collision = self_collision  # (and the empty scene cache)

    @property
    def fused(self) -> bool:
        """Whether the compiled pass runs (module docstring); set it to True, False or None."""
        return self._fused

    @fused.setter
    def fused(self, fused: bool | None) -> None:
        self._fused = self._check_fused(check_flag(fused, "fused", optional=True))
        self._scenes: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()

    @property
    def self_collision(self) -> bool:
        """Whether exact self-collision enters the distance (module docstring)."""
        return self._self_collision

    @self_collision.setter
    def self_collision(self, on: bool) -> None:
        self._self_collision = check_flag(on, "self_collision")
        self._scenes = weakref.WeakKeyDictionary()

    def with_contact_offset(self, contact_offset: float) -> GraphDistNet3DModel:
        """This model with contact-only pairs offset by ``contact_offset`` (m); the copy shares
        the network and the per-scene caches (they do not depend on the offset)."""
        twin = copy.copy(self)
        twin.contact_offset = check_offset(contact_offset)
        return twin

    def _check_fused(self, fused: bool | None) -> bool:
        """The ``fused`` setting resolved (module docstring); InputError when True cannot be."""
        why = fused3d.refusal(self.config)
        if why is None and self.dtype not in _NUMPY:
            why = f"dtype {self.dtype}: the pass runs float32 or float64"
        if fused and why is not None:
            raise InputError(f"fused: the compiled GraphDistNet-3D pass cannot serve ({why})")
        return why is None if fused is None else fused

    def check_scene(self, scene: Scene3D) -> None:
        """InputError unless ``scene`` lies within what the weights were trained on: the card's
        robot with its bare link geometry, obstacles of the card's training environment
        (:func:`.fit.check_fits3d`)."""
        check_fits3d(self.card, self.config.rim, scene)

    def _cache(self, scene: Scene3D) -> _SceneCache:
        cached = self._scenes.get(scene)
        if cached is None:
            self.check_scene(scene)
            graph = robot_graph3d(scene.robot, self.config.rim)
            obs = obstacle_input([scene_graph3d(scene, rim=self.config.rim)], self.dtype)
            with torch.inference_mode(False), torch.no_grad():
                feats = self.net.obstacle_pass(obs)
            checker = None
            if self.self_collision and len(scene.robot.self_pairs):
                checker = Checker3D(Scene3D(scene.robot, ()))
            nbr, mask = robot_tensors(graph)
            packed = None
            if self.fused:
                packed = fused3d.pack(self.net, feats, graph, _NUMPY[self.dtype])
            cached = _SceneCache(graph, nbr, mask, feats, checker, packed)
            self._scenes[scene] = cached
        return cached

    def _chunks(self, n: int) -> list[slice]:
        return [slice(s, min(s + self.chunk, n)) for s in range(0, n, self.chunk)]

    def learned_distance(self, scene: Scene3D, q) -> np.ndarray:
        """(B,) d̂ of the robot–obstacle distance alone (m), all finite (else InputError)."""
        with overflow_guard(self):
            d = self._learned_distance(scene, q)
        finite(self, d)
        return d

    def _learned_distance(self, scene: Scene3D, q) -> np.ndarray:
        check_scene(scene, "3d", "a planar model (gdnplan.load_model of planar weights)")
        q = scene.robot.check_q(q)
        with torch_threads(self.threads):
            c = self._cache(scene)
            if c.packed is not None:
                d, _ = fused3d.run(c.packed, c.graph.positions(q), grad=False)
                return d.astype(np.float64)
            with torch.inference_mode():
                out = [
                    self.net(self._tensor(c.graph.positions(q[s])), c.nbr, c.nbr_mask, c.feats)
                    for s in self._chunks(len(q))
                ]
        return torch.cat(out).double().numpy()

    def learned_distance_and_grad(self, scene: Scene3D, q) -> tuple[np.ndarray, np.ndarray]:
        """(B,), (B, dof): d̂ of the robot–obstacle distance (m) and ∂d̂/∂q (m/rad), all
        finite (else InputError)."""
        with overflow_guard(self):
            d, g = self._learned_distance_and_grad(scene, q)
        finite(self, d, g)
        return d, g

    def _learned_distance_and_grad(self, scene: Scene3D, q) -> tuple[np.ndarray, np.ndarray]:
        check_scene(scene, "3d", "a planar model (gdnplan.load_model of planar weights)")
        q = scene.robot.check_q(q)
        ds, gs = [], []
        with torch_threads(self.threads):
            c = self._cache(scene)
            if c.packed is not None:
                nodes, jac = c.graph.kinematics(q)
                d, dx = fused3d.run(c.packed, nodes, grad=True)
                return d.astype(np.float64), c.graph.pullback(nodes, jac, dx.astype(np.float64))
            for s in self._chunks(len(q)):
                nodes, jac = c.graph.kinematics(q[s])
                x = self._tensor(nodes).requires_grad_(True)
                with torch.enable_grad():
                    d = self.net(x, c.nbr, c.nbr_mask, c.feats)
                    (dx,) = torch.autograd.grad(d.sum(), x)
                ds.append(d.detach().double().numpy())
                gs.append(c.graph.pullback(nodes, jac, dx.double().numpy()))
        return np.concatenate(ds), np.concatenate(gs)

    def _tensor(self, x: np.ndarray) -> torch.Tensor:
        return torch.as_tensor(x, dtype=self.dtype)

    def distance(self, scene: Scene3D, q) -> np.ndarray:
        """(B,) min(d̂, exact self-collision distance) (m) of q (B, dof) or (dof,)."""
        d = self.learned_distance(scene, q)
        checker = self._cache(scene).self_checker
        if checker is None:
            return d
        own = checker.evaluate(q, contact_offset=self.contact_offset).distance
        return np.minimum(d, own)

    def distance_and_grad(self, scene: Scene3D, q) -> tuple[np.ndarray, np.ndarray]:
        """((B,), (B, dof)): the distance of :meth:`distance` and its gradient (m/rad)."""
        d, g = self.learned_distance_and_grad(scene, q)
        checker = self._cache(scene).self_checker
        if checker is None:
            return d, g
        res = checker.evaluate(q, gradient=True, contact_offset=self.contact_offset)
        own = res.distance < d
        return np.where(own, res.distance, d), np.where(own[:, None], res.gradient, g)
