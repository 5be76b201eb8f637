"""GraphDistNet as a :class:`~gdnplan.models.DistanceModel`: scene cache, chunks, threads,
and the gradient ∂d̂/∂q through the robot graph's pullback."""

from __future__ import annotations

import functools
import itertools
import weakref
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import torch

from ...errors import InputError
from ...graph import GraphBatch, RobotGraph, obstacle_graph, robot_graph, scene_obstacles
from ...scene import Scene, check_scene
from ..checks import check_fits
from ..outputs import finite, overflow_guard
from ..settings import Checked, Fixed, check_chunk, check_device, check_dtype, check_flag, placed
from ..threads import check_threads, torch_threads
from . import fused as fused_kernel
from . import fused_net
from .lean import SceneGraph
from .network import GraphDistNet

# graph nodes per inference pass: the per-pass fixed cost favours large chunks, memory small
# ones (docs/decisions.md#chunk-nodes)
CHUNK_NODES = 9000


class GraphDistNetModel:
    """A trained GraphDistNet as a :class:`~gdnplan.models.DistanceModel`.

    q → node positions (:meth:`~gdnplan.graph.RobotGraph.kinematics`, float64) → d̂ in
    ``dtype`` (float32 by default) in equal chunks of at most ``chunk`` samples (default: about
    ``CHUNK_NODES`` graph nodes per pass, the nodes a configuration runs being N_r + N_o, or N_r
    for one-way networks) → ∂d̂/∂p_n by autograd on the robot node coordinates p_n (B, N, 2)
    → ∂d̂/∂q = Σ_n (∂p_n/∂q)ᵀ ∂d̂/∂p_n
    (:meth:`~gdnplan.graph.RobotGraph.pullback`, float64). ``cross="soft_knn"`` networks run
    :meth:`GraphDistNet.lean`, others the reference :meth:`GraphDistNet.forward`. The graphs of
    a scene are built once per scene object (scenes are immutable) and cached. Results are
    float64 numpy arrays. Inference runs with ``threads`` torch threads (None: the library
    default, 1; :mod:`gdnplan.models.threads`), the caller's count restored after each call;
    the compiled whole pass runs its tiles on that many threads.

    ``fused`` selects the kernel of the lean path's ring messages: True the fused numba kernels
    (:mod:`.fused`: on CPU, hidden layers of one width, numba installed), False the
    torch reference (:class:`~.layers._LeakyRingMessages`), None (default) the fused kernels
    where they serve the network, else the reference. The two compute the same function
    (tests/test_graphdistnet_fused.py). With the fused kernels, networks that
    :func:`.fused_net.serves` (one-way or two-way; node distances one-way) run whole in one
    compiled pass (:mod:`.fused_net`: d̂ and ∂d̂/∂nodes without torch;
    tests/test_graphdistnet_fused_net.py).
    """

    name = "graphdistnet"
    threads = Checked(check_threads)  # settable later, checked as here (models/settings.py)
    chunk = Checked(check_chunk)
    dtype, device = Fixed(), Fixed()

    def __init__(
        self,
        net: GraphDistNet,
        card: dict | None = None,
        chunk: int | None = None,
        dtype: torch.dtype = torch.float32,
        device: str | torch.device = "cpu",
        threads: int | None = None,
        fused: bool | None = None,
    ):
        self.dtype = check_dtype(dtype)
        self.device = check_device(device)
        self.chunk = chunk
        self.net = placed(net, self.device, self.dtype)
        self.threads = threads
        self.config = net.config
        self.card = card or {}
        self.source: str | None = None  # the weights file it was loaded from (messages)
        self.fused = fused

    @property
    def fused(self) -> bool:
        """Whether the fused kernels run (class docstring); set it to True, False or None."""
        return self._fused

    @fused.setter
    def fused(self, fused: bool | None) -> None:
        self._fused = self._check_fused(check_flag(fused, "fused", optional=True))
        self._scenes: weakref.WeakKeyDictionary[Scene, _SceneCache] = weakref.WeakKeyDictionary()

    def _check_fused(self, fused: bool | None) -> bool:
        """The ``fused`` setting resolved (class docstring); InputError when True cannot be."""
        c = self.config
        serves = (
            fused_kernel.supports(c.mlp)
            and c.cross == "soft_knn"
            and self.dtype in (torch.float32, torch.float64)
            and self.device.type == "cpu"
        )
        if fused and not serves:
            why = "numba is not installed" if not fused_kernel.AVAILABLE else "not this network"
            raise InputError(
                "fused: the fused kernel serves soft_knn networks with hidden layers of one "
                f"width, float32 on CPU ({why}); use fused=None or False"
            )
        return serves if fused is None else fused

    def check_scene(self, scene: Scene) -> None:
        """InputError unless the weights were trained for ``scene``'s robot (models/checks.py)."""
        check_fits(self.card, scene)

    def _graphs(self, scene: Scene) -> _SceneCache:
        """The (cached) robot graph, obstacle graph and lean scene graph of ``scene``."""
        cached = self._scenes.get(scene)
        if cached is None:
            self.check_scene(scene)
            graph = robot_graph(scene.robot)
            polys, sizes = scene_obstacles([scene])
            obstacles = obstacle_graph(polys, sizes, None, device=self.device, dtype=self.dtype)
            lean = (
                self.net.scene_graph(graph, obstacles) if self.config.cross == "soft_knn" else None
            )
            whole = None
            if self.fused and fused_net.serves(self.config):
                whole = fused_net.pack(self.net, lean, _NUMPY[self.dtype])
            cached = self._scenes[scene] = _SceneCache(graph, obstacles, lean, whole)
        return cached

    def _estimate(
        self, graphs: _SceneCache, nodes: torch.Tensor, gen: torch.Generator | None
    ) -> torch.Tensor:
        """d̂ (B,) (m) of robot nodes (B, N_r, 2) (m)."""
        if graphs.lean is not None:
            return self.net.lean(nodes, graphs.lean, self.fused)
        robot = graphs.robot.batch(nodes, device=self.device, dtype=self.dtype)
        return self.net(robot, _repeat(graphs.obstacles, len(nodes)), gen)

    def _chunks(self, n: int, graphs: _SceneCache) -> list[slice]:
        """n samples in ⌈n / chunk⌉ near-equal slices (77 → one, not 64 + 13: the fixed cost
        per pass matters at the planner's batch sizes)."""
        chunk = self.chunk
        if chunk is None:
            lean = graphs.lean
            one_way = lean is not None and lean.fixed is not None
            nodes = graphs.robot.n_nodes + (0 if one_way else graphs.obstacles.nodes.shape[1])
            chunk = max(16, CHUNK_NODES // nodes)
        edges = np.linspace(0, n, -(-n // chunk) + 1).round().astype(int)
        return [slice(a, b) for a, b in itertools.pairwise(edges)]

    def _generator(self) -> torch.Generator | None:
        return torch.Generator().manual_seed(0) if self.config.cross == "argmax" else None

    def _tensor(self, nodes: np.ndarray) -> torch.Tensor:
        return torch.as_tensor(nodes, dtype=self.dtype, device=self.device)

    def distance(self, scene: Scene, q: np.ndarray) -> np.ndarray:
        """(B,) estimated signed distances (m) of q (B, dof) or (dof,); InputError when the
        network gives a NaN or infinite one (:mod:`gdnplan.models.outputs`)."""
        with overflow_guard(self):
            d = self._distance(scene, q)
        finite(self, d)
        return d

    def _distance(self, scene: Scene, q: np.ndarray) -> np.ndarray:
        check_scene(scene, "planar", "a GraphDistNet-3D model (gdnplan.load_model of 3-D weights)")
        q = scene.robot.check_q(q)
        if len(q) == 0:  # an empty batch (the network has no empty pass): (0,)
            self._graphs(scene)  # the scene is still checked
            return np.zeros(0)
        with torch_threads(self.threads) as threads:
            graphs = self._graphs(scene)  # outside inference mode: the cache serves autograd too
            if graphs.whole is not None:
                nodes = graphs.robot.positions(q)
                d, _ = fused_net.run(graphs.whole, nodes, grad=False, threads=threads)
                return d.astype(np.float64)
            gen = self._generator()
            with torch.inference_mode():
                out = [
                    self._estimate(graphs, self._tensor(graphs.robot.positions(q[part])), gen)
                    for part in self._chunks(len(q), graphs)
                ]
                return torch.cat(out).double().cpu().numpy()

    def distance_and_grad(self, scene: Scene, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """((B,), (B, dof)): d̂ (m) and ∂d̂/∂q (m/rad), all finite (else InputError)."""
        with overflow_guard(self):
            d, g = self._distance_and_grad(scene, q)
        finite(self, d, g)
        return d, g

    def _distance_and_grad(self, scene: Scene, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        check_scene(scene, "planar", "a GraphDistNet-3D model (gdnplan.load_model of 3-D weights)")
        q = scene.robot.check_q(q)
        if len(q) == 0:  # an empty batch: (0,) and (0, dof), the scene still checked
            self._graphs(scene)
            return np.zeros(0), np.zeros(q.shape)
        with torch_threads(self.threads) as threads:
            graphs = self._graphs(scene)
            if graphs.whole is not None:
                return _whole(graphs, q, threads)
            gen = self._generator()
            ds, gs = [], []
            for part in self._chunks(len(q), graphs):
                taped = self._taped(graphs, q[part], gen)
                ds.append(taped.d.detach())
                gs.append(taped.grad(graphs.robot))
        return torch.cat(ds).double().cpu().numpy(), np.concatenate(gs)

    def distance_deferred_grad(
        self, scene: Scene, q: np.ndarray
    ) -> tuple[np.ndarray, Callable[[], np.ndarray]]:
        """d̂ (B,) (m) now and a function returning ∂d̂/∂q (B, dof) (m/rad) when called.

        The forward pass keeps its autograd graph; the backward pass runs only if the gradient
        is asked for (then once). A line search evaluates trial points it often rejects: they
        cost the forward pass alone (about half of :meth:`distance_and_grad`). Meant for
        planner-sized batches: every chunk's graph is held until the gradient is taken. The
        whole-network pass (:mod:`.fused_net`) computes the gradient with d̂ instead: its
        backward follows each tile's forward in cache (about half the forward's cost again),
        cheaper than a second forward for the 70 % or so of planner calls that ask for it
        (docs/decisions.md, 2026-12-02 fused2). Both are checked finite (InputError).
        """
        with overflow_guard(self):
            d, grad = self._distance_deferred_grad(scene, q)
        finite(self, d)

        def gradient() -> np.ndarray:
            with overflow_guard(self):
                g = grad()
            finite(self, d, g)
            return g

        return d, gradient

    def _distance_deferred_grad(
        self, scene: Scene, q: np.ndarray
    ) -> tuple[np.ndarray, Callable[[], np.ndarray]]:
        check_scene(scene, "planar", "a GraphDistNet-3D model (gdnplan.load_model of 3-D weights)")
        q = scene.robot.check_q(q)
        if len(q) == 0:
            d, g = self.distance_and_grad(scene, q)
            return d, lambda: g
        threads = self.threads
        with torch_threads(threads) as count:
            graphs = self._graphs(scene)
            if graphs.whole is not None:  # the compiled pass: its gradient at once (below)
                d, g = _whole(graphs, q, count)
                return d, lambda: g
            gen = self._generator()
            tapes = [self._taped(graphs, q[part], gen) for part in self._chunks(len(q), graphs)]

        @functools.cache
        def gradient() -> np.ndarray:
            with torch_threads(threads):
                return np.concatenate([t.grad(graphs.robot) for t in tapes])

        return torch.cat([t.d.detach() for t in tapes]).double().cpu().numpy(), gradient

    def _taped(self, graphs: _SceneCache, q: np.ndarray, gen: torch.Generator | None) -> _Tape:
        """The forward pass of q (B, dof) with its autograd graph on the node coordinates."""
        nodes, joints = graphs.robot.kinematics(q)
        x = self._tensor(nodes).requires_grad_(True)
        with torch.enable_grad():
            d = self._estimate(graphs, x, gen)
        return _Tape(nodes, joints, x, d)


@dataclass(frozen=True)
class _Tape:
    """A forward pass awaiting its backward pass: node positions (B, N_r, 2) (m) and their
    joints, the autograd leaf x (their tensor) and d̂ (B,)."""

    nodes: np.ndarray
    joints: np.ndarray
    x: torch.Tensor
    d: torch.Tensor

    def grad(self, robot: RobotGraph) -> np.ndarray:
        """∂d̂/∂q (B, dof): autograd to the node coordinates, then the robot's pullback."""
        (dx,) = torch.autograd.grad(self.d.sum(), self.x)
        return robot.pullback(self.nodes, self.joints, dx.double().cpu().numpy())


@dataclass(frozen=True)
class _SceneCache:
    """The graphs of one scene: robot structure, obstacle graph (1, N_o), lean constants and,
    where :mod:`.fused_net` serves, the packed arrays of its whole-network pass."""

    robot: RobotGraph
    obstacles: GraphBatch
    lean: SceneGraph | None
    whole: fused_net.PackedNetwork | None = None


_NUMPY = {torch.float32: np.float32, torch.float64: np.float64}


def _whole(graphs: _SceneCache, q: np.ndarray, threads: int) -> tuple[np.ndarray, np.ndarray]:
    """(d̂ (B,), ∂d̂/∂q (B, dof)) of q by the whole-network pass on up to ``threads`` threads
    and the robot's pullback."""
    nodes, joints = graphs.robot.kinematics(q)
    d, dx = fused_net.run(graphs.whole, nodes, grad=True, threads=threads)
    return d.astype(np.float64), graphs.robot.pullback(nodes, joints, dx.astype(np.float64))


def _repeat(graph: GraphBatch, b: int) -> GraphBatch:
    """A single graph (1, N) repeated B times (views, no copy)."""
    parts = (graph.nodes, graph.prev, graph.next, graph.mask)
    return GraphBatch(*(t.expand(b, *t.shape[1:]) for t in parts))
