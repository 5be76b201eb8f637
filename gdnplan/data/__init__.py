"""Datasets of configurations, obstacle sets and coal labels, written as resumable ``.npz`` shards.

Modules by concern:

* :mod:`.dataset`: :class:`Dataset` (the arrays of a split), loading shards, joining datasets;
* :mod:`.sampling`: the samples of a shard for the environments a–e (uniform, or near the
  collision boundary), labelled by coal;
* :mod:`.ur5e_samples`: the samples of the ``ur5e`` environment (gripper states, fetch layouts,
  random boxes, near-contact samples around the task);
* :mod:`.shards`: :func:`generate`, which writes a split as shards and resumes it.

The names below are the public ones (``from gdnplan.data import load, generate, …``).
"""

from ..geometry import pad_polygons
from .dataset import (
    DATA_DIR,
    ENVS,
    FIELDS,
    ROBOT_FIELDS,
    SPLITS,
    Dataset,
    concat,
    env_robot,
    load,
    split_dir,
    variant_robot,
)
from .sampling import (
    BOUNDARY_BAND,
    RANDOM_ENVS,
    SHARD_SIZE,
    make_shard,
    near_boundary,
    split_samples,
)
from .shards import MANIFEST, MANIFEST_OPTIONS, generate, shard_paths
from .ur5e_samples import (
    CANONICAL_SHARE,
    FETCH_SEED_BASE,
    NEAR_REFS,
    NEAR_SEGMENTS,
    NEAR_SIGMA,
    UR5E_LAYOUTS,
    make_ur5e_shard,
    near_reference,
    random_boxes,
    ur5e_layout_seeds,
)

__all__ = [
    "BOUNDARY_BAND",
    "CANONICAL_SHARE",
    "DATA_DIR",
    "ENVS",
    "FETCH_SEED_BASE",
    "FIELDS",
    "MANIFEST",
    "MANIFEST_OPTIONS",
    "NEAR_REFS",
    "NEAR_SEGMENTS",
    "NEAR_SIGMA",
    "RANDOM_ENVS",
    "ROBOT_FIELDS",
    "SHARD_SIZE",
    "SPLITS",
    "UR5E_LAYOUTS",
    "Dataset",
    "concat",
    "env_robot",
    "generate",
    "load",
    "make_shard",
    "make_ur5e_shard",
    "near_boundary",
    "near_reference",
    "pad_polygons",
    "random_boxes",
    "shard_paths",
    "split_dir",
    "split_samples",
    "ur5e_layout_seeds",
    "variant_robot",
]
