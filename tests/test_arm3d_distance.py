"""3-D signed distance of gdnplan.arm3d (gdnplan.arm3d.distance3d) against independent truth:
a QP over the shapes' vertices, the brute-force minimum (the broad phase changes nothing).
The gradients' finite-difference tests are in test_arm3d_gradient3d.py."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st
from scipy.optimize import minimize
from scipy.spatial import ConvexHull

from gdnplan.arm3d import (
    Checker3D,
    Coal3DModel,
    Scene3D,
    box_obstacle,
    load_robot3d,
    random_boxes,
    signed_distance3d,
    signed_distance3d_and_grad,
)
from gdnplan.errors import InputError
from gdnplan.models import DistanceModel


def qp_distance(a: np.ndarray, b: np.ndarray) -> float:
    """Distance of the convex hulls of point sets a (n, 3) and b (m, 3), independent of coal:
    the distance from the origin to the Minkowski difference hull{aᵢ − bⱼ} (Qhull), a QP in
    three unknowns: min ‖x‖² s.t. the hull's facets n_f · x + o_f ≤ 0 (SLSQP)."""
    diff = (a[:, None] - b[None]).reshape(-1, 3)
    hull = ConvexHull(diff)
    eq = hull.equations
    cons = {
        "type": "ineq",
        "fun": lambda x: -(eq[:, :3] @ x + eq[:, 3]),
        "jac": lambda x: -eq[:, :3],
    }
    x0 = diff[hull.vertices].mean(0)
    res = minimize(
        lambda x: (x @ x, 2 * x),
        x0,
        jac=True,
        constraints=[cons],
        method="SLSQP",
        options={"ftol": 1e-14, "maxiter": 500},
    )
    assert np.max(eq[:, :3] @ res.x + eq[:, 3]) <= 1e-9, res.message  # feasible: in the hull
    return float(np.linalg.norm(res.x))


def box_corners(obstacle) -> np.ndarray:
    half = np.asarray(obstacle.shape.halfSide)
    corners = np.array(np.meshgrid([-1, 1], [-1, 1], [-1, 1])).reshape(3, -1).T * half
    return corners @ np.asarray(obstacle.pose.getRotation()).T + obstacle.pose.getTranslation()


def test_separated_mesh_hull_distances_match_a_qp_over_the_vertices(panda_scene):
    checker = Checker3D(panda_scene, tolerance=1e-10)
    robot = panda_scene.robot
    rng = np.random.default_rng(4)
    compared = {"obstacle": 0, "self": 0}
    for q in robot.random_configurations(12, rng):
        tf = robot.shape_placements(q)
        d, _ = checker.pair_distances(q)
        world = [
            np.asarray(s.shape.points()) @ t[:3, :3].T + t[:3, 3]
            if hasattr(s.shape, "points")
            else None
            for s, t in zip(robot.shapes, tf, strict=True)
        ]
        for k in rng.permutation(checker.n_pairs)[:60]:
            a, b = checker.pair_a[k], checker.pair_b[k]
            if world[a] is None or not 0.005 < d[0, k] < 0.5:
                continue
            if checker.is_self[k]:
                if world[b] is None:
                    continue
                other, kind = world[b], "self"
            else:
                other, kind = box_corners(panda_scene.obstacles[b]), "obstacle"
            assert d[0, k] == pytest.approx(qp_distance(world[a], other), abs=2e-6)
            compared[kind] += 1
    assert compared["obstacle"] >= 10 and compared["self"] >= 3


@given(
    seed=st.integers(0, 1000), cap=st.sampled_from([0.02, 0.1, 0.5, np.inf]), per_link=st.booleans()
)
@settings(max_examples=25, deadline=None)
def test_the_broad_phase_never_changes_the_minimum_below_the_cap(seed, cap, per_link):
    robot = load_robot3d("ur5e")
    scene = random_boxes(robot, 20, seed=seed)
    checker = Checker3D(scene)
    q = robot.random_configurations(3, np.random.default_rng(seed))
    brute, narrow_all = checker.pair_distances(q)  # every pair, no cap
    assert np.all(narrow_all == checker.n_pairs)
    res = checker.evaluate(q, per_link=per_link, cap=cap, contact_offset=0.0)  # every pair
    if per_link:
        for link in range(robot.n_links):
            involved = (checker.link_a == link) | (checker.link_b == link)
            expected = np.minimum(brute[:, involved].min(1), cap)
            np.testing.assert_array_equal(res.distance[:, link], expected)
    else:
        np.testing.assert_array_equal(res.distance, np.minimum(brute.min(1), cap))
    assert np.all(res.narrow <= checker.n_pairs)
    off = checker.evaluate(q, per_link=per_link, cap=cap, broad_phase=False, contact_offset=0.0)
    np.testing.assert_array_equal(off.distance, res.distance)


def test_capped_results_have_zero_gradient_and_no_pair():
    robot = load_robot3d("ur5e")
    far = Scene3D(robot, [box_obstacle((0.1, 0.1, 0.1), (5.0, 0.0, 0.0))])
    checker = Checker3D(far)
    # the home pose: self pairs are > 1 cm apart; a 5 mm cap leaves nothing to evaluate
    res = checker.evaluate([0.0, -1.57, 1.57, -1.57, -1.57, 0.0], cap=0.005, gradient=True)
    assert res.distance[0] == 0.005 and res.pair[0] == -1 and not res.gradient.any()
    with pytest.raises(InputError, match="cap"):
        checker.evaluate(np.zeros(6), cap=float("nan"))


def test_coal3d_model_is_a_distance_model(ur5e_scene):
    model = Coal3DModel()
    assert isinstance(model, DistanceModel)
    q = ur5e_scene.robot.random_configurations(4, np.random.default_rng(0))
    d, g = model.distance_and_grad(ur5e_scene, q)
    assert d.shape == (4,) and g.shape == (4, 6)
    np.testing.assert_array_equal(d, model.distance(ur5e_scene, q))
    d2, g2 = signed_distance3d_and_grad(ur5e_scene, q, per_link=True)
    assert d2.shape == (4, ur5e_scene.robot.n_links) and g2.shape == (4, d2.shape[1], 6)
    np.testing.assert_allclose(d2.min(1), d)


@settings(max_examples=12, deadline=None)
@given(st.integers(0, 3), st.booleans(), st.booleans())
@example(0, False, False)  # the audit's case: IndexError on an empty batch
def test_a_batch_of_any_size_has_the_shapes_of_its_rows(batch, per_link, gradient):
    """(B,) or (B, L) distances and (…, dof) gradients for every B, 0 included (an empty
    batch raised IndexError; the planar functions return empty arrays), each row equal to its
    configuration alone."""
    robot = load_robot3d("ur5e")
    scene = Scene3D(robot, [box_obstacle((0.1, 0.1, 0.1), (0.5, 0.0, 0.3))])
    q = robot.random_configurations(batch, np.random.default_rng(batch))
    tail = (robot.n_links,) if per_link else ()
    if gradient:
        d, g = signed_distance3d_and_grad(scene, q, per_link=per_link)
        assert g.shape == (batch, *tail, robot.dof)
    else:
        d = signed_distance3d(scene, q, per_link=per_link)
    assert d.shape == (batch, *tail)
    for i in range(batch):
        assert np.array_equal(d[i], signed_distance3d(scene, q[i], per_link=per_link)[0])


@pytest.mark.parametrize("tolerance", [-1.0, 0.0, np.nan, 1e300, True, "x", [1e-6]])
def test_a_checker_tolerance_outside_its_range_is_refused(ur5e_scene, tolerance):
    """A negative or NaN GJK/EPA tolerance made every distance 0, a string raised Boost's
    ArgumentError, a list TypeError (unhashable) in the checker cache."""
    from gdnplan.arm3d import checker3d

    with pytest.raises(InputError, match=r"^tolerance: expected None or a number in \(0, 0.01\]"):
        checker3d(ur5e_scene, tolerance)


@pytest.mark.parametrize("value", [10**400, -(10**400)], ids=["+huge int", "-huge int"])
def test_cap_and_contact_offset_refuse_ints_past_the_float_range(ur5e_scene, value):
    q = np.zeros((1, 6))
    with pytest.raises(InputError, match=r"^cap: expected a number \(m\) or inf"):
        signed_distance3d(ur5e_scene, q, cap=value)
    with pytest.raises(InputError, match=r"^contact_offset: expected a number \(m\) or inf"):
        Coal3DModel(contact_offset=value)


@pytest.mark.parametrize(
    ("robot", "size", "message"),
    [
        ("ur5e", (0.1, 0.2, 5.0), r"^size: expected \[smallest, largest\]"),  # 5.0 was ignored
        ("ur5e", (0.1,), r"^size: expected \[smallest, largest\]"),  # IndexError
        ("ur5e", {0.1, 0.2}, r"^size: expected \[smallest, largest\]"),  # TypeError
        ("planar2", (0.05, 0.2), r"^robot: expected a Robot3D, got Robot"),  # AttributeError
    ],
)
def test_random_boxes_check_robot_and_size(robot, size, message):
    import gdnplan as gp

    robot = load_robot3d(robot) if robot == "ur5e" else gp.load_robot(robot)
    with pytest.raises(InputError, match=message):
        random_boxes(robot, 3, size=size)


@settings(max_examples=25, deadline=None)
@given(share=st.floats(0.0, 1.0, exclude_max=True), n=st.integers(1, 50))
@example(share=1.0 - 1e-6, n=20)  # a clearance just below the reach drew boxes for ever
@example(share=0.95, n=50)
def test_random_boxes_never_loop_for_ever_near_the_reach(share, n):
    """Box centres are drawn in the half ball of the reach and kept beyond base_clearance
    from the base axis: a clearance that leaves too small a share of the draws (MIN_ROOM) is
    refused, naming the largest one accepted; any other draws its boxes (at least MIN_ROOM of
    the draws land, so about n / MIN_ROOM draws at most are expected)."""
    import math

    from gdnplan.arm3d.scene3d import MIN_ROOM, workspace_radius

    robot = load_robot3d("ur5e")
    reach = workspace_radius(robot)
    clearance = share * reach
    room = math.pi / 6 * (1 - share**2) ** 1.5
    if room < MIN_ROOM:
        with pytest.raises(InputError, match=r"^base_clearance: .* give at most") as e:
            random_boxes(robot, n, base_clearance=clearance)
        most = float(str(e.value).rsplit("at most ", 1)[1].split(" m")[0])
        random_boxes(robot, 1, base_clearance=most * (1 - 1e-3))  # the one named is accepted
        return
    scene = random_boxes(robot, n, base_clearance=clearance)
    centres = np.array([o.pose.getTranslation() for o in scene.obstacles])
    assert len(centres) == n and np.all(np.hypot(centres[:, 0], centres[:, 1]) >= clearance)
