"""GraphDistNet (paper §IV): message passing between a robot graph and an obstacle graph.

Notation (one sample): nodes i of the union graph G_ro = G_r ∪ G_o with coordinates x_i⁽⁰⁾
(normalised: (p − origin) / scale, scale = the arm's reach) and features x_i⁽ᵏ⁾ ∈ R^{d_h}.
Layer k = 0 … K − 1 updates every node with its ring neighbours N(i) = {prev(i), next(i)} and
one cross-graph partner j_c:

    x_i⁽ᵏ⁺¹⁾ = Σ_{j ∈ N(i) ∪ {i}} h_k( z_j⁽ᵏ⁾ − z_i⁽ᵏ⁾ ‖ z̄_i⁽ᵏ⁾ − z_i⁽ᵏ⁾ ),
    z_i⁽⁰⁾ = x_i⁽⁰⁾,  z_i⁽ᵏ⁾ = (x_i⁽⁰⁾ ‖ x_i⁽ᵏ⁾),                            (Eq. 2, 5)

h_k an MLP R^4 → R^{d_h} (k = 0), R^{2 d_h + 4} → R^{d_h} (k > 0). The cross term z̄_i:

* ``cross="argmax"`` (the paper): z̄_i = z_{j_c} with j_c uniform random over the other graph at
  k = 0, and j_c = argmax_j a⁽ᵏ⁾ᵀ x_j⁽ᵏ⁾ over the other graph afterwards (one partner per graph).
  d̂ is then random (k = 0) and jumps where the argmax switches.
* ``cross="soft_knn"`` (planner default): a soft partner among the k + 1 nearest nodes c of the
  other graph (squared distances d²_c in ascending order, d²_{k+1} the farthest of them):

      z̄_i = Σ_c w_ic z_c,  w_ic ∝ φ_ic exp(−d²_ic / τ_k + a⁽ᵏ⁾ᵀ x_c⁽ᵏ⁾),  φ_ic = d²_{k+1} − d²_ic,

  (no score at k = 0, τ_k learned). φ vanishes on the (k + 1)-th node, so a node entering or
  leaving the candidate set does so with zero weight: d̂ is a deterministic, continuous
  function of the node positions (and piecewise smooth).

One-way cross edges (``two_way=False``, beyond the paper): only robot nodes take a cross
partner; obstacle nodes have z̄_i = z_i (no cross term), so x_o⁽ᵏ⁾, their scores and their
readouts y_o⁽ᵏ⁾ depend on the scene alone. Inference computes them once per scene, and the
work per configuration is the robot graph's (N_r of N = N_r + N_o nodes) plus its soft
partners among the cached obstacle features.

Distance-aware nodes (``node_distance``, beyond the paper): every node also knows its signed
distance s_i to the other graph's polygons (:func:`signed_ring_distance`; robot nodes to the
obstacles, obstacle nodes to the links; normalised units, negative inside). h_k sees only
differences z_j − z_i, so s_i enters as an absolute per-node term of the first linear layer:
pre_ij = W_loc (z_j − z_i) + W_rel (z̄_i − z_i) + s_i w_k + b, the same on the three edges of i
(one-way networks: s = 0 on obstacle nodes, whose features stay scene-only). Between two
polygons that are apart the distance is min_i s_i (a closest pair has a vertex at one end), so
``min_readout`` reads d̂ as a correction of the soft minimum m = −τ_m log Σ_i exp(−s_i / τ_m):
d̂ = scale · (m + MLP(y_r ‖ y_o ‖ m)). The MLP then learns what m misses: penetration depth,
and overlaps without a vertex inside the other polygon (two thin bars crossing). s and m are
continuous in the node positions, so d̂ stays continuous. ``probe_split`` p adds the points
splitting every ring edge into p pieces to m's minimum (not to the graphs): a bar crossing a
square then has points inside it. ``correction_band`` β hands d̂ to m away from contact:
d̂ = scale · (g · MLP(…) + (1 − g) · m), g = σ(8 (1 − scale · m / β)) ≈ 1 in overlap and
< 3·10⁻⁴ once m is more than 2β apart, where d̂ is m itself (exact up to the soft minimum)
instead of the MLP's estimate; a network trained without m (head input m at weight 0) keeps
its function in overlap when it gets the band.

Readout (Eq. 9–11): per graph g ∈ {r, o} and layer k = 1 … K, α_i = softmax_{i∈g}(a⁽ᵏ⁾ᵀ x_i⁽ᵏ⁾),
y_g⁽ᵏ⁾ = f(Σ_i α_i x_i⁽ᵏ⁾); y_g = max_k y_g⁽ᵏ⁾ element-wise; d̂ = scale · MLP(y_r ‖ y_o) (m).

Implementation: dense padded tensors; the first linear layer of h_k is applied per node, not
per edge, since W (z_j − z_i) = W z_j − W z_i: with W = [W_loc W_rel] and u = z W_locᵀ,
v = z W_relᵀ (per node), the edge pre-activation is u_j − u_i + v̄_i − v_i + b.

Inference (:class:`GraphDistNetModel`, ``soft_knn``) runs :meth:`GraphDistNet.lean`, the same
function for one scene without padding: ring neighbours by one shared index, the cross terms
as dense batched products, the last linear layer of h_k after the sum over the edges and, for
LeakyReLU, the edge MLP with a hand-written backward (:class:`_LeakyRingMessages`). Tests
prove it equal to :meth:`GraphDistNet.forward` (values and gradients). Where numba is installed
(a core dependency), the edge MLP runs by the fused kernels of :mod:`.fused` instead, tile by
tile in cache (and one-way cross terms over the candidates only); ``GraphDistNetModel(fused=…)``
selects them (default: wherever they serve the network), tests prove them equal to the torch
path on every shipped weights file. Networks without node distances (one-way or two-way) and
one-way networks with them run whole in one compiled call (:mod:`.fused_net`,
:mod:`.fused_net_distances`).

Modules: :mod:`.config` (options), :mod:`.geometry` (candidates, ring distances),
:mod:`.layers` (MLPs, readout softmax, ring messages), :mod:`.network` (the module and its
padded forward), :mod:`.lean` (the lean inference path), :mod:`.model` (the DistanceModel
wrapper), :mod:`.load` (weights files: :func:`load_graphdistnet_weights`), :mod:`.fused` (the
fused numba kernels of the lean path), :mod:`.fused_net` with :mod:`.fused_net_kernels`,
:mod:`.fused_net_readout` and :mod:`.fused_net_backward` (the whole network, forward and
backward to the node positions, as one compiled pass: the default for the soft-kNN networks it
serves).
"""

from .config import GraphDistNetConfig
from .geometry import (
    PAD_DIST2,
    _nearest_edge_and_inside,
    _pairwise_d2,
    nearest_candidates,
    nearest_columns,
    nearest_obstacle_nodes,
    signed_ring_distance,
)
from .layers import LEAKY_SLOPE, _activation, _LeakyRingMessages, masked_softmax, mlp
from .lean import LeanInference, ObstacleFeatures, SceneGraph, _cross_mix, _softmax_small
from .load import load_graphdistnet, load_graphdistnet_weights
from .model import CHUNK_NODES, GraphDistNetModel, _repeat, _SceneCache, _Tape
from .network import GraphDistNet, Union

__all__ = [
    "CHUNK_NODES",
    "LEAKY_SLOPE",
    "PAD_DIST2",
    "GraphDistNet",
    "GraphDistNetConfig",
    "GraphDistNetModel",
    "LeanInference",
    "ObstacleFeatures",
    "SceneGraph",
    "Union",
    "_LeakyRingMessages",
    "_SceneCache",
    "_Tape",
    "_activation",
    "_cross_mix",
    "_nearest_edge_and_inside",
    "_pairwise_d2",
    "_repeat",
    "_softmax_small",
    "load_graphdistnet",
    "load_graphdistnet_weights",
    "masked_softmax",
    "mlp",
    "nearest_candidates",
    "nearest_columns",
    "nearest_obstacle_nodes",
    "signed_ring_distance",
]
