"""Gradients of the 3-D signed distance (gdnplan.arm3d.gradient3d) against central finite
differences: meshes (Panda), primitives (UR5e), and a point cloud given as a coal octree, apart
and in contact."""

from __future__ import annotations

import coal
import numpy as np
import pytest

from gdnplan.arm3d import Checker3D, Scene3D, load_robot3d, obstacle


def fd_checks(checker: Checker3D, qs: np.ndarray, per_link: bool = False, h: float = 1e-5):
    """(gradient, central difference, distance) of every configuration whose minimising pair
    is the same at q ± h e_j for every joint (away from switches) and needed no coal retry."""
    out = []
    dof = checker.robot.dof
    for q in qs:
        before = checker.fallbacks
        res = checker.evaluate(q, per_link, gradient=True)
        fd = np.zeros_like(res.gradient[0])
        same = True
        for j in range(dof):
            e = np.zeros(dof)
            e[j] = h
            plus, minus = checker.evaluate(q + e, per_link), checker.evaluate(q - e, per_link)
            same &= np.array_equal(plus.pair, res.pair) and np.array_equal(minus.pair, res.pair)
            fd[..., j] = (plus.distance[0] - minus.distance[0]) / (2 * h)
        if same and checker.fallbacks == before:
            out.append((res.gradient[0], fd, res.distance[0]))
    return out


def test_panda_mesh_gradients_match_central_differences_apart_and_in_penetration(panda_scene):
    checker = Checker3D(panda_scene, tolerance=1e-9)
    qs = panda_scene.robot.random_configurations(60, np.random.default_rng(2))
    checks = fd_checks(checker, qs)
    assert len(checks) >= 40
    depths = np.array([d for _, _, d in checks])
    assert (depths < 0).sum() >= 3 and (depths > 0).sum() >= 20  # both regimes are tested
    for g, fd, _ in checks:
        assert np.linalg.norm(g - fd) <= 1e-5 * max(np.linalg.norm(fd), 1e-2)


def test_panda_per_link_gradients_match_central_differences(panda_scene):
    checker = Checker3D(panda_scene, tolerance=1e-9)
    qs = panda_scene.robot.random_configurations(6, np.random.default_rng(3))
    checks = fd_checks(checker, qs, per_link=True)
    assert checks
    for g, fd, _ in checks:
        err = np.linalg.norm(g - fd, axis=-1)
        assert np.all(err <= 1e-5 * np.maximum(np.linalg.norm(fd, axis=-1), 1e-2))


def test_ur5e_primitive_gradients_match_central_differences(ur5e_scene):
    """Cylinders are curved: GJK's witness direction converges only like the square root of
    its distance tolerance (and EPA fails on them below ~1e-8), so the bounds here are 1e-4
    relative at the median, 1e-3 for 90 % and 1e-2 for all (1e-5 for polytopes above)."""
    checker = Checker3D(ur5e_scene, tolerance=1e-8)
    qs = ur5e_scene.robot.random_configurations(60, np.random.default_rng(2))
    checks = fd_checks(checker, qs)
    assert len(checks) >= 30
    depths = np.array([d for _, _, d in checks])
    assert (depths < 0).sum() >= 3 and (depths > 0).sum() >= 10
    errors = [np.linalg.norm(g - fd) / max(np.linalg.norm(fd), 1e-1) for g, fd, _ in checks]
    assert np.median(errors) <= 1e-4 and np.quantile(errors, 0.9) <= 1e-3
    assert max(errors) <= 1e-2


@pytest.fixture(scope="module")
def cloud_scene():
    """The UR5e before a wall-like point cloud (x = 0.4 m) given to coal as an octree."""
    rng = np.random.default_rng(0)
    n = 400
    pts = np.column_stack([np.full(n, 0.4), rng.uniform(-0.3, 0.3, n), rng.uniform(0, 0.6, n)])
    return Scene3D(load_robot3d("ur5e"), [obstacle(coal.makeOctree(pts, 0.02), name="cloud")])


def smooth_octree_checks(checker: Checker3D, qs, h: float = 1e-5):
    """:func:`fd_checks` of the configurations whose minimum is a robot–octree pair and whose
    witness normal stays put at q ± h e_j: an octree is a union of voxel boxes, and where the
    nearest voxel changes within ±h the distance has a kink no central difference resolves."""
    out = []
    for q in qs:
        res = checker.evaluate(q)
        if res.pair[0] >= checker.n_obstacle_pairs:
            continue
        steps = np.vstack([q + h * np.eye(len(q)), q - h * np.eye(len(q))])
        if np.abs(checker.evaluate(steps).normal - res.normal[0]).max() > 1e-3:
            continue
        out += fd_checks(checker, [q], h=h)
    return out


def test_octree_obstacle_gradients_match_central_differences_apart_and_in_contact(cloud_scene):
    """coal orders an octree pair's witnesses (octree, shape) whatever order it is given; the
    gradient had the opposite sign of the central difference (cosine −1) before
    :mod:`gdnplan.arm3d.narrow3d` swapped them back."""
    checker = Checker3D(cloud_scene, tolerance=1e-8)
    qs = cloud_scene.robot.random_configurations(200, np.random.default_rng(0))
    checks = smooth_octree_checks(checker, qs)
    depths = np.array([d for _, _, d in checks])
    assert (depths < 0).sum() >= 5 and (depths > 0).sum() >= 3  # both regimes are tested
    assert all(g @ fd > 0.999 * np.linalg.norm(g) * np.linalg.norm(fd) for g, fd, _ in checks)
    # curved link shapes: the bounds of the UR5e primitive test above
    errors = [np.linalg.norm(g - fd) / max(np.linalg.norm(fd), 1e-1) for g, fd, _ in checks]
    assert np.median(errors) <= 1e-4 and np.quantile(errors, 0.9) <= 1e-3
    assert max(errors) <= 1e-2
