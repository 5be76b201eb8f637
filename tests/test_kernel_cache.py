"""The numba cache guard (models/graphdistnet/kernel_cache.py): a change to any kernel source
deletes every cached kernel, an unchanged tree keeps them."""

import re
from pathlib import Path

from gdnplan.models.graphdistnet import kernel_cache


def tree(root: Path) -> tuple[Path, Path]:
    """A fake gdnplan/models with two kernel files and a cached kernel in each package."""
    planar, spatial = root / "graphdistnet", root / "graphdistnet3d"
    for package, name in ((planar, "fused_net_distances.py"), (spatial, "fused3d_kernels.py")):
        (package / "__pycache__").mkdir(parents=True)
        (package / name).write_text("x = 1\n")
        (package / "__pycache__" / f"{name[:-3]}.f-10.py311.nbi").write_bytes(b"i")
        (package / "__pycache__" / f"{name[:-3]}.f-10.py311.1.nbc").write_bytes(b"c")
    (planar / "lean.py").write_text("y = 2\n")  # not a kernel: no effect on the digest
    return planar, spatial


def cached(root: Path) -> list[str]:
    return sorted(p.name for p in root.rglob("*.nb[ic]"))


def test_a_changed_kernel_source_purges_every_cached_kernel(tmp_path):
    planar, spatial = tree(tmp_path)
    assert kernel_cache.sources(tmp_path) == [
        planar / "fused_net_distances.py",
        spatial / "fused3d_kernels.py",
    ]
    assert kernel_cache.purge_stale(tmp_path)  # no stamp yet: purge, write it
    assert cached(tmp_path) == []
    (spatial / "__pycache__" / "fused3d_kernels.f-10.py311.nbi").write_bytes(b"i")
    assert not kernel_cache.purge_stale(tmp_path)  # same sources: the cache stays
    (planar / "lean.py").write_text("y = 3\n")
    assert not kernel_cache.purge_stale(tmp_path)
    assert cached(tmp_path) == ["fused3d_kernels.f-10.py311.nbi"]
    (planar / "fused_net_distances.py").write_text("x = 2\n")  # a callee changed
    assert kernel_cache.purge_stale(tmp_path)
    assert cached(tmp_path) == []  # the 3-D caller's cache too


def test_the_installed_kernels_are_all_in_the_digest():
    names = {p.name for p in kernel_cache.sources()}
    kernels = {"fused.py", "fused_net_kernels.py", "fused_net_backward.py", "gemm.py",
               "fused_net_distances.py", "fused3d.py", "fused3d_kernels.py",
               "fused3d_backward.py"}  # fmt: skip
    assert kernels <= names
    package = Path(kernel_cache.__file__).parents[2]  # all of gdnplan
    decorated = re.compile(r"^\s*@(_jit|numba\.)", re.MULTILINE)  # a compiled function
    jitted = {p.name for p in package.rglob("*.py") if decorated.search(p.read_text())}
    assert jitted <= names  # every module with cached kernels is covered
