"""Datasets of configurations, obstacle sets and coal labels, written as resumable ``.npz`` shards.

A sample is a configuration q drawn uniformly within the joint limits, the obstacle polygons of
its scene and the coal labels: the signed distance f_cd(q) (m) and its gradient ∂f/∂q (m/rad).
Fixed environments (a, c) share one scene; random environments (b, d, e) draw a new obstacle
set per sample with ``make_scene(env, seed=scene_seed)``, where

    scene_seed = seed · 10⁸ + index     (index = position of the sample in the split),

so a split is a pure function of (env, seed, n) and train (seed 0) and test (seed 1) never
share a scene. Shards of ``SHARD_SIZE`` samples are written by a pool of processes, each to a
temporary file renamed when complete (:func:`gdnplan.files.atomic_path`).

Resuming: the folder's ``manifest.json`` records the settings of its split (env, seed, near,
shard size), written before the first shard. Running :func:`generate` again with the same
settings continues the split: shard k holds samples k · SHARD_SIZE … of the n asked for, so
shards that exist with exactly that size are kept, a shorter last shard of a smaller earlier
n is made again at its full size, and the missing ones are made; the folder then holds the
same n samples as a one-shot run of n. Other settings (another env, seed or near), a smaller n
than the folder already holds, or shards without a manifest are refused with an InputError
naming the setting, never mixed into the split.

The ``ur5e`` environment (the fetch robot, paper §V-C) varies the robot as well: each sample
draws a gripper state (open, closed, holding), a storage layout and 1–3 random boxes around
it. Building a random fetch layout searches for free grasps (≈ 45 ms), so each split draws its
layouts from a fixed pool of ``UR5E_LAYOUTS`` fetch seeds

    layout_seed = FETCH_SEED_BASE + seed · 10⁶ + k,   k = 0 … UR5E_LAYOUTS − 1,

disjoint between splits and from the benchmark's seeds (< FETCH_SEED_BASE); the train split
also uses the canonical layout (fetch seed 0) for a ``CANONICAL_SHARE`` of its samples. The
obstacles are the fetch scene's for that gripper state (table, storage, and the stick unless
held) plus the boxes; when holding, the robot carries the layout's stick (length 0.15–0.30 m,
width 0.02–0.04 m). ``scene_seed`` is the fetch seed of the sample's layout. With
``near`` > 0, that fraction of the samples is concentrated near the task's contacts:

    q = clip(q_ref + ε, limits),  ε ~ N(0, σ² I),  log σ ~ U(log σ_min, log σ_max),

q_ref drawn from the layout's configurations of that gripper state (open/closed: q_home,
q_pregrasp, q_grasp; holding: q_grasp, q_lift, q_out) or from the joint-space segments of the
task through the entrance (open/closed: q_pregrasp → q_grasp; holding: q_lift → q_out, at a
uniform fraction s: q_ref = q_a + s (q_b − q_a)), where uniform samples rarely fall, and
(σ_min, σ_max) = NEAR_SIGMA: the log-uniform scale puts samples at every distance from the
contacts, down to the millimetres of the stick resting on its shelf (at 0.005 rad the tcp moves
≈ 3 mm).

For the environments a–e, ``near`` > 0 concentrates that fraction of the samples at the
collision boundary instead (beyond the paper, for AUC and gradients where they matter): a
near-boundary sample is q uniform within the limits conditioned on |f(q)| < ``BOUNDARY_BAND``,
drawn by rejection (uniform candidates labelled by coal, the first ones inside the band kept).

Shard arrays (n samples, P obstacles of at most V vertices, N robot nodes):

========== ================= ====================================================
q          (n, dof) float64  joint angles (rad)
nodes      (n, N, 2) float32 robot graph nodes (link polygon vertices) at q (m)
obstacles  (n, P, V, 2)      obstacle polygons, CCW, zero-padded (m)
sizes      (n, P) int32      vertex count of each polygon (0 = no polygon)
d          (n,) float64      coal signed distance (m)
grad       (n, dof) float64  coal ∂f/∂q
scene_seed (n,) int64        seed of the sample's scene
gripper    (n,) int8         ur5e only: index into GRIPPER_STATES (open, closed, holding)
stick      (n, 2) float64    ur5e only: held stick (length, width) (m); 0 unless holding
========== ================= ====================================================

For the fixed-robot environments ``gripper`` and ``stick`` are None and ``nodes`` has one N;
for ``ur5e`` ``nodes`` is zero-padded to the largest robot graph.
"""

from __future__ import annotations

import json
import os
from dataclasses import dataclass
from functools import lru_cache
from multiprocessing import get_context
from pathlib import Path

import numpy as np
from tqdm import tqdm

from .distance import signed_distance, signed_distance_and_grad
from .errors import InputError, UnknownNameError
from .files import atomic_path, write_text
from .geometry import pad_polygons
from .robot import Robot, load_robot
from .scene import ENV_ROBOT, Scene, clear_of_base, make_scene
from .ur5e import GRIPPER_STATES, TABLE_V

SHARD_SIZE = 2500
RANDOM_ENVS = ("b", "d", "e")
SPLITS = {"train": (0, 50_000), "test": (1, 5_000)}  # split -> (seed, paper's size)
DATA_DIR = Path("data")  # default dataset root, relative to the working directory
FIELDS = ("q", "nodes", "obstacles", "sizes", "d", "grad", "scene_seed")
ROBOT_FIELDS = ("gripper", "stick")  # per-sample robot variant (ur5e only)
ENVS = (*ENV_ROBOT, "ur5e")
UR5E_LAYOUTS = 300  # fetch layouts per split
FETCH_SEED_BASE = 10_000  # first fetch seed of the dataset layouts (benchmarks use smaller)
CANONICAL_SHARE = 0.1  # fraction of ur5e train samples on the canonical layout (fetch seed 0)
BOUNDARY_BAND = 0.03  # m: near-boundary samples of a–e have |f| below this
NEAR_SIGMA = (0.005, 0.2)  # rad: range of the log-uniform spread of the near-contact samples
NEAR_REFS = {  # gripper state -> fetch configurations the near-contact samples spread around
    "open": ("q_home", "q_pregrasp", "q_grasp"),
    "closed": ("q_home", "q_pregrasp", "q_grasp"),
    "holding": ("q_grasp", "q_lift", "q_out"),
}
NEAR_SEGMENTS = {  # gripper state -> task segments (joint-space lines) through the entrance
    "open": (("q_pregrasp", "q_grasp"),),
    "closed": (("q_pregrasp", "q_grasp"),),
    "holding": (("q_lift", "q_out"),),
}


@dataclass(frozen=True)
class Dataset:
    """Samples of one environment (see the module docstring for the arrays)."""

    env: str
    q: np.ndarray
    nodes: np.ndarray
    obstacles: np.ndarray
    sizes: np.ndarray
    d: np.ndarray
    grad: np.ndarray
    scene_seed: np.ndarray
    gripper: np.ndarray | None = None
    stick: np.ndarray | None = None

    def __len__(self) -> int:
        return len(self.q)

    def subset(self, index: np.ndarray | slice) -> Dataset:
        """The samples at ``index`` (an index array or a slice)."""
        extra = (
            None if getattr(self, f) is None else getattr(self, f)[index] for f in ROBOT_FIELDS
        )
        return Dataset(self.env, *(getattr(self, f)[index] for f in FIELDS), *extra)

    def robot(self, i: int) -> Robot:
        """The robot of sample i (the environment's, or the ur5e with the sample's gripper)."""
        if self.gripper is None:
            return env_robot(self.env)
        return variant_robot(int(self.gripper[i]), *(float(x) for x in self.stick[i]))

    def variants(self) -> dict[tuple[int, float, float], np.ndarray]:
        """Sample indices per robot variant (gripper code, stick length, stick width).

        Fixed-robot environments have one variant, ``(-1, 0.0, 0.0)``.
        """
        if self.gripper is None:
            return {(-1, 0.0, 0.0): np.arange(len(self))}
        keys = np.column_stack([self.gripper.astype(float), self.stick])
        uniq, inverse = np.unique(keys, axis=0, return_inverse=True)
        inverse = inverse.reshape(-1)
        return {
            (int(k[0]), float(k[1]), float(k[2])): np.flatnonzero(inverse == j)
            for j, k in enumerate(uniq)
        }

    def scene(self, i: int) -> Scene:
        """The scene of sample i (its robot and obstacle polygons)."""
        polys = [self.obstacles[i, p, :s] for p, s in enumerate(self.sizes[i]) if s > 0]
        polys = tuple(np.asarray(p, float) for p in polys)
        return Scene(self.robot(i), polys, name=self.env)

    def save(self, path: Path | str, compact: bool = False) -> None:
        """Write one ``.npz`` (atomic). ``compact`` drops ``nodes`` and stores float32 polygons."""
        path = Path(path)
        arrays = {f: getattr(self, f) for f in FIELDS}
        arrays |= {f: getattr(self, f) for f in ROBOT_FIELDS if getattr(self, f) is not None}
        if compact:
            arrays["nodes"] = np.zeros((len(self), 0, 2), np.float32)
            arrays["obstacles"] = arrays["obstacles"].astype(np.float32)
        with atomic_path(path, "shard") as tmp, open(tmp, "wb") as f:
            np.savez_compressed(f, env=np.array(self.env), **arrays)


def env_robot(env: str) -> Robot:
    """The robot of an environment (``ur5e``: the UR5e with its gripper open)."""
    return load_robot("ur5e", gripper="open") if env == "ur5e" else make_scene(env).robot


def variant_robot(gripper: int, stick_length: float = 0.0, stick_width: float = 0.0) -> Robot:
    """The UR5e with gripper state ``GRIPPER_STATES[gripper]`` (holding: the stick's size, m);
    ``gripper = −1`` is not a variant (fixed-robot environments use :func:`env_robot`)."""
    state = GRIPPER_STATES[gripper]
    if state != "holding":
        return load_robot("ur5e", gripper=state)
    return load_robot("ur5e", gripper=state, stick_length=stick_length, stick_width=stick_width)


@lru_cache(maxsize=2048)
def _fetch_base(layout_seed: int, gripper: str) -> Scene:
    return make_scene("fetch", seed=layout_seed, gripper=gripper)


def random_boxes(rng: np.random.Generator, robot: Robot, k: int) -> list[np.ndarray]:
    """k random rectangles around the storage, clear of the robot's base (CCW (4, 2), m).

    Centre u ∈ [0.25, 1.4], v ∈ [TABLE_V, TABLE_V + 1], sides ∈ [0.04, 0.25], rotation
    θ ∈ [0, π/2); drawn again while within ``robot.base_radius`` of joint 1.
    """
    boxes: list[np.ndarray] = []
    while len(boxes) < k:
        c = np.array([rng.uniform(0.25, 1.4), rng.uniform(TABLE_V, TABLE_V + 1.0)])
        half = rng.uniform(0.02, 0.125, 2)
        t = rng.uniform(0, np.pi / 2)
        rot = np.array([[np.cos(t), -np.sin(t)], [np.sin(t), np.cos(t)]])
        box = c + (np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]]) * half) @ rot.T
        if clear_of_base(box, robot):
            boxes.append(box)
    return boxes


def ur5e_layout_seeds(seed: int) -> np.ndarray:
    """Fetch seeds of the layout pool of the split with ``seed`` (see the module docstring)."""
    return FETCH_SEED_BASE + seed * 10**6 + np.arange(UR5E_LAYOUTS, dtype=np.int64)


def near_reference(rng: np.random.Generator, info: dict, gripper: str) -> np.ndarray:
    """(3,) q_ref of a near-contact sample: one of the NEAR_REFS configurations or a point of a
    NEAR_SEGMENTS segment, uniformly over the union of both lists (module docstring)."""
    refs, segments = NEAR_REFS[gripper], NEAR_SEGMENTS[gripper]
    k = int(rng.integers(len(refs) + len(segments)))
    if k < len(refs):
        return info[refs[k]]
    a, b = (info[name] for name in segments[k - len(refs)])
    return a + rng.uniform() * (b - a)


def make_ur5e_shard(seed: int, start: int, n: int, near: float = 0.0) -> Dataset:
    """Samples ``start … start + n − 1`` of the ``ur5e`` split with ``seed``.

    Per sample (rng seeded by (seed, start)): gripper state uniform over GRIPPER_STATES, a
    layout from the split's pool (the canonical one with probability CANONICAL_SHARE except in
    the test split), 1–3 random boxes, q uniform within the limits or, with probability
    ``near``, near a task configuration (module docstring); labels from coal.
    """
    rng = np.random.default_rng([seed, start, 7])
    pool = ur5e_layout_seeds(seed)
    gripper = rng.integers(0, len(GRIPPER_STATES), n).astype(np.int8)
    layout = pool[rng.integers(0, len(pool), n)]
    if seed != SPLITS["test"][0]:
        layout[rng.random(n) < CANONICAL_SHARE] = 0
    is_near = rng.random(n) < near if near > 0 else np.zeros(n, bool)  # uniform: rng as before
    q = np.empty((n, 3))
    stick = np.zeros((n, 2))
    d, grad = np.empty(n), np.empty((n, 3))
    polys, nodes = [], []
    for i in range(n):
        base = _fetch_base(int(layout[i]), GRIPPER_STATES[gripper[i]])
        robot = base.robot
        if GRIPPER_STATES[gripper[i]] == "holding":
            stick[i] = robot.info["stick_length"], robot.info["stick_width"]
        obstacles = (*base.obstacles, *random_boxes(rng, robot, int(rng.integers(1, 4))))
        scene = Scene(robot, obstacles, name="ur5e")
        q[i] = robot.sample(1, seed=[seed, start + i])[0]
        if is_near[i]:
            ref = near_reference(rng, base.info, GRIPPER_STATES[gripper[i]])
            sigma = np.exp(rng.uniform(*np.log(NEAR_SIGMA)))
            q[i] = np.clip(ref + rng.normal(0.0, sigma, 3), robot.lower, robot.upper)
        di, gi = signed_distance_and_grad(scene, q[i][None])
        d[i], grad[i] = di[0], gi[0]
        polys.append(list(obstacles))
        nodes.append(robot.node_positions(q[i][None])[0])
    obstacles_arr, sizes = pad_polygons(polys)
    n_nodes = max(len(x) for x in nodes)
    padded = np.zeros((n, n_nodes, 2), np.float32)
    for i, x in enumerate(nodes):
        padded[i, : len(x)] = x
    return Dataset("ur5e", q, padded, obstacles_arr, sizes, d, grad, layout, gripper, stick)


def near_boundary(scene: Scene, k: int, rng: np.random.Generator) -> np.ndarray:
    """(k, dof) configurations uniform within the limits conditioned on |f| < BOUNDARY_BAND
    (rejection sampling in batches of uniform candidates labelled by coal)."""
    robot = scene.robot
    batch = min(4096, max(256, 40 * k))
    kept = [np.empty((0, robot.dof))]
    found = 0
    for _ in range(10_000):
        if found >= k:
            return np.concatenate(kept)[:k]
        candidates = robot.sample(batch, seed=rng.integers(2**63))
        inside = candidates[np.abs(signed_distance(scene, candidates)) < BOUNDARY_BAND]
        kept.append(inside)
        found += len(inside)
    raise InputError(f"near: no configurations within {BOUNDARY_BAND} m of contact in {scene.name}")


def make_shard(env: str, seed: int, start: int, n: int, near: float = 0.0) -> Dataset:
    """Samples ``start … start + n − 1`` of the split of ``env`` with ``seed`` (``near``:
    fraction of near-contact samples, see the module docstring)."""
    if env == "ur5e":
        return make_ur5e_shard(seed, start, n, near)
    base = make_scene(env, seed=0)
    robot = base.robot
    q = robot.sample(n, seed=[seed, start])
    scene_seed = seed * 10**8 + start + np.arange(n, dtype=np.int64)
    rng = np.random.default_rng([seed, start, 11])
    is_near = rng.random(n) < near if near > 0 else np.zeros(n, bool)
    if env in RANDOM_ENVS:
        scenes = [make_scene(env, seed=int(s)) for s in scene_seed]
        for i in np.flatnonzero(is_near):
            q[i] = near_boundary(scenes[i], 1, rng)[0]
        labels = [signed_distance_and_grad(s, qi[None]) for s, qi in zip(scenes, q, strict=True)]
        d = np.concatenate([lab[0] for lab in labels])
        grad = np.concatenate([lab[1] for lab in labels])
        polys = [list(s.obstacles) for s in scenes]
    else:
        q[is_near] = near_boundary(base, int(is_near.sum()), rng)
        chunks = [signed_distance_and_grad(base, c) for c in np.array_split(q, -(-n // 500))]
        d, grad = (np.concatenate(x) for x in zip(*chunks, strict=True))  # no nested pools
        polys = [list(base.obstacles)] * n
    obstacles, sizes = pad_polygons(polys)
    nodes = robot.node_positions(q).astype(np.float32)
    return Dataset(env, q, nodes, obstacles, sizes, d, grad, scene_seed)


def _write_shard(job: tuple[str, int, int, int, str, float]) -> int:
    env, seed, start, n, path, near = job
    make_shard(env, seed, start, n, near).save(path)
    return n


def shard_paths(out_dir: Path | str, n: int) -> list[tuple[int, int, Path]]:
    """(start, size, path) of every shard of an n-sample split in ``out_dir``."""
    out_dir = Path(out_dir)
    return [
        (start, min(SHARD_SIZE, n - start), out_dir / f"shard_{start // SHARD_SIZE:04d}.npz")
        for start in range(0, n, SHARD_SIZE)
    ]


MANIFEST = "manifest.json"
MANIFEST_OPTIONS = {"env": "--env", "seed": "--seed", "near": "--near", "shard_size": "SHARD_SIZE"}


def _check_manifest(out_dir: Path, settings: dict) -> None:
    """Write ``out_dir``'s manifest, or check that it records ``settings`` (InputError if not)."""
    path = out_dir / MANIFEST
    if not path.exists():
        if any(out_dir.glob("shard_*.npz")):
            raise InputError(
                f"data: {out_dir} holds shards but no {MANIFEST}, so their settings cannot be "
                "checked; move them away or generate into another --data folder"
            )
        write_text(path, json.dumps(settings, indent=2) + "\n", "--data")
        return
    try:
        recorded = json.loads(path.read_text())
    except (ValueError, OSError) as e:
        raise InputError(f"data: {path} is not a readable manifest ({e}); move the folder") from e
    for key, option in MANIFEST_OPTIONS.items():
        if not isinstance(recorded, dict) or recorded.get(key) != settings[key]:
            was = recorded.get(key) if isinstance(recorded, dict) else None
            raise InputError(
                f"{option}: {out_dir} holds a split made with {key} = {was!r}, not "
                f"{settings[key]!r} ({MANIFEST}); use the same setting to continue it, or "
                "another --data folder"
            )


def _shard_size(path: Path) -> int | None:
    """Samples in the shard ``path`` (None when it cannot be read: it is made again)."""
    try:
        with np.load(path) as z:
            return len(z["q"])
    except (OSError, ValueError, KeyError):
        return None


def _missing_shards(out_dir: Path, n: int) -> list[tuple[int, int, Path]]:
    """The shards of an n-sample split still to make in ``out_dir`` (module docstring);
    InputError when the folder holds more than n samples."""
    plan = shard_paths(out_dir, n)
    names = {p.name for _, _, p in plan}
    shards = [p for p in out_dir.glob("shard_*.npz") if not p.name.endswith(".tmp.npz")]
    extra = [p for p in shards if p.name not in names]
    sizes = {p: _shard_size(p) for _, _, p in plan if p.exists()}
    if extra or any((sizes.get(p) or 0) > k for _, k, p in plan):
        held = sum(_shard_size(p) or 0 for p in shards)
        raise InputError(
            f"--n: {out_dir} already holds {held} samples of this split, more than n = {n}; "
            f"ask for n ≥ {held} to continue it, or use another --data folder"
        )
    return [(s, k, p) for s, k, p in plan if sizes.get(p) != k]


def generate(
    env: str,
    n: int,
    seed: int,
    out_dir: Path | str,
    workers: int | None = None,
    near: float = 0.0,
) -> Path:
    """Write an n-sample split of ``env`` as shards in ``out_dir``, or continue the one there
    (finished shards are kept; other settings are refused, see the module docstring).

    Args:
        env: environment name (``"a"`` … ``"e"``, ``"ur5e"``).
        n: number of samples.
        seed: split seed (train 0, test 1 by convention, see ``SPLITS``).
        out_dir: directory of the shards (created).
        workers: processes (default: all cores).
        near: fraction of near-contact samples (module docstring: around the fetch task for
            ``ur5e``, at the collision boundary for a–e).

    Returns:
        ``out_dir``.
    """
    if env not in ENVS:
        raise UnknownNameError(f"env: unknown environment {env!r}; choose one of {list(ENVS)}")
    if n < 1:
        raise InputError(f"n: expected a positive number of samples, got {n}")
    if not 0.0 <= near <= 1.0:
        raise InputError(f"near: expected a fraction in [0, 1], got {near}")
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    settings = {"env": env, "seed": int(seed), "near": float(near), "shard_size": SHARD_SIZE}
    _check_manifest(out_dir, settings)
    jobs = [(env, seed, s, k, str(p), near) for s, k, p in _missing_shards(out_dir, n)]
    done = n - sum(j[3] for j in jobs)
    workers = min(workers or os.cpu_count() or 1, max(len(jobs), 1))
    with tqdm(total=n, initial=done, desc=f"generate {env} → {out_dir}", unit="sample") as bar:
        if workers < 2:
            for job in jobs:
                bar.update(_write_shard(job))
        else:
            with get_context("fork").Pool(workers) as pool:
                for k in pool.imap_unordered(_write_shard, jobs):
                    bar.update(k)
    return out_dir


def load(path: Path | str, n: int | None = None) -> Dataset:
    """Load a split (a directory of shards, or one ``.npz``), at most its first n samples."""
    path = Path(path)
    files = sorted(path.glob("shard_*.npz")) if path.is_dir() else [path] * path.exists()
    files = [f for f in files if not f.name.endswith(".tmp.npz")]
    if not files:
        raise InputError(f"data: no shards in {path}; run `gdnplan generate` first")
    parts = []
    total = 0
    for f in files:
        with np.load(f) as z:
            parts.append({k: z[k] for k in ("env", *FIELDS, *ROBOT_FIELDS) if k in z})
        total += len(parts[-1]["q"])
        if n is not None and total >= n:
            break
    return _join(parts, n)


def concat(datasets: list[Dataset]) -> Dataset:
    """One dataset of the samples of ``datasets`` in order (polygons padded to the largest)."""
    if not datasets:
        raise InputError("concat: no datasets")
    parts = [
        {f: getattr(ds, f) for f in (*FIELDS, *ROBOT_FIELDS) if getattr(ds, f) is not None}
        | {"env": ds.env}
        for ds in datasets
    ]
    if len({p["env"] for p in parts}) > 1:
        envs = [ds.env for ds in datasets]
        raise InputError(f"concat: datasets of different environments {envs}")
    return _join(parts, None)


def _join(parts: list[dict], n: int | None) -> Dataset:
    """Pad the arrays of ``parts`` (dicts of the shard fields) alike and join them."""
    n_poly = max(p["obstacles"].shape[1] for p in parts)
    n_vert = max(p["obstacles"].shape[2] for p in parts)
    n_nodes = max(p["nodes"].shape[1] for p in parts)
    for p in parts:
        o, s = p["obstacles"], p["sizes"]
        p["obstacles"] = np.pad(
            o, ((0, 0), (0, n_poly - o.shape[1]), (0, n_vert - o.shape[2]), (0, 0))
        )
        p["sizes"] = np.pad(s, ((0, 0), (0, n_poly - s.shape[1])))
        if "gripper" in p:
            nd = p["nodes"]
            p["nodes"] = np.pad(nd, ((0, 0), (0, n_nodes - nd.shape[1]), (0, 0)))
    arrays = [np.concatenate([p[f] for p in parts])[:n] for f in FIELDS]
    extra = [
        np.concatenate([p[f] for p in parts])[:n] if all(f in p for p in parts) else None
        for f in ROBOT_FIELDS
    ]
    return Dataset(str(parts[0]["env"]), *arrays, *extra)


def split_dir(env: str, split: str, root: Path | str = DATA_DIR) -> Path:
    """``data/<env>/<split>``."""
    return Path(root) / env / split
