"""A dataset of configurations, obstacle sets and coal labels (:class:`Dataset`), loading a
split of ``.npz`` shards, and joining datasets.

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

import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import InputError
from ..files import atomic_path
from ..flags import check_flag
from ..robot import Robot, load_robot
from ..scene import ENV_ROBOT, Scene, make_scene
from ..ur5e import GRIPPER_STATES
from .shard_read import check_planar, read_npz

SPLITS = {"train": (0, 50_000), "test": (1, 5_000)}  # split -> (seed, paper's size)
DATA_DIR = Path("data")  # default dataset root, relative to the working directory
FIELDS = ("q", "nodes", "obstacles", "sizes", "d", "grad", "scene_seed")
ROBOT_FIELDS = ("gripper", "stick")  # per-sample robot variant (ur5e only)
ENVS = (*ENV_ROBOT, "ur5e")


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
        compact = check_flag(compact, "compact")
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


def load(path: Path | str, n: int | None = None) -> Dataset:
    """Load a split (a directory of shards, or one ``.npz``), at most its first n samples
    (a UserWarning when it holds fewer: all of them are used); every shard checked as it is
    read (:mod:`.shard_read`), InputError naming the file."""
    path = Path(path)
    files = sorted(path.glob("shard_*.npz")) if path.is_dir() else [path] * path.exists()
    files = [f for f in files if not f.name.endswith(".tmp.npz")]
    if not files:
        raise InputError(f"data: no shards in {path}; run `gdnplan generate` first")
    parts = []
    total = 0
    for f in files:
        arrays = read_npz(f)
        check_planar(arrays, f, FIELDS)
        parts.append({k: arrays[k] for k in ("env", *FIELDS, *ROBOT_FIELDS) if k in arrays})
        _check_same_split(parts[0], parts[-1], files[0], f)
        total += len(parts[-1]["q"])
        if n is not None and total >= n:
            break
    if n is not None and total < n:
        warnings.warn(
            f"data: {path} holds {total} samples, fewer than the {n} asked for; using all "
            f"{total} (generate more with `gdnplan generate`)",
            stacklevel=2,
        )
    return _join(parts, n)


def _check_same_split(first: dict, part: dict, first_file: Path, file: Path) -> None:
    """InputError unless the shard arrays ``part`` (of ``file``) have the environment and
    joint count of ``first`` (of ``first_file``)."""
    a, b = (str(first["env"]), first["q"].shape[1]), (str(part["env"]), part["q"].shape[1])
    if a != b:
        raise InputError(
            f"data: shard {file} holds samples of environment {b[0]!r} ({b[1]} joints), "
            f"{first_file.name} of {a[0]!r} ({a[1]} joints): a split folder holds one "
            "environment's shards; move the others out"
        )


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
