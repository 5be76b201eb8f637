"""Bad inputs to every public scene-taking function: wrong scene kinds, non-numbers in
configurations, bad seeds, flat polygons. Each is an InputError naming the argument (and, for
the other scene kind, the function to use), never an AttributeError or TypeError."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp
from scipy.interpolate import PchipInterpolator

import gdnplan as gp
from gdnplan import arm3d, ccd_curve, distance, exact
from gdnplan.arm3d.scene3d import workspace_radius
from gdnplan.geometry import as_polygon
from gdnplan.robot import as_batch

PLANAR = gp.make_scene("b")
ROBOT3D = arm3d.load_robot3d("ur5e")
SCENE3D = arm3d.random_boxes(ROBOT3D, 3, seed=0)
Q2, Q3 = np.zeros(2), np.zeros(6)


def _curve(dof: int) -> PchipInterpolator:
    return PchipInterpolator([0.0, 1.0], np.zeros((2, dof)))


PLANAR_FUNCTIONS = {  # name -> call(scene); the planar ones
    "signed_distance": lambda s: gp.signed_distance(s, Q2),
    "signed_distance_and_grad": lambda s: gp.signed_distance_and_grad(s, Q2),
    "certify_path": lambda s: gp.certify_path(s, np.stack([Q2, Q2 + 0.1])),
    "verify_path": lambda s: gp.verify_path(s, np.stack([Q2, Q2 + 0.1])),
    "checker": lambda s: distance.checker(s),
    "CoalChecker": lambda s: distance.CoalChecker(s),
    "witness": lambda s: distance.witness(s, Q2),
    "CoalModel.distance": lambda s: gp.CoalModel().distance(s, Q2),
    "CoalModel.distance_and_grad": lambda s: gp.CoalModel().distance_and_grad(s, Q2),
}
FUNCTIONS_3D = {
    "signed_distance3d": lambda s: arm3d.signed_distance3d(s, Q3),
    "signed_distance3d_and_grad": lambda s: arm3d.signed_distance3d_and_grad(s, Q3),
    "certify_path3d": lambda s: arm3d.certify_path3d(s, np.stack([Q3, Q3 + 0.1])),
    "checker3d": lambda s: arm3d.checker3d(s),
    "Checker3D": lambda s: arm3d.Checker3D(s),
    "Coal3DModel.distance": lambda s: arm3d.Coal3DModel().distance(s, Q3),
    "Coal3DModel.distance_and_grad": lambda s: arm3d.Coal3DModel().distance_and_grad(s, Q3),
}
EITHER = {  # the scene-kind protocol and the curve certificate take both kinds
    "exact_distance": lambda s: exact.exact_distance(s, Q2),
    "certify": lambda s: exact.certify(s, np.stack([Q2, Q2])),
    "closest_pair": lambda s: exact.closest_pair(s, Q2),
    "certify_curve": lambda s: ccd_curve.certify_curve(s, _curve(2)),
}
NOT_SCENES = [None, "b", 5, 2.5, [], PLANAR.robot, ROBOT3D]
ALL = {**PLANAR_FUNCTIONS, **FUNCTIONS_3D, **EITHER}


@pytest.mark.parametrize("bad", NOT_SCENES, ids=repr)
@pytest.mark.parametrize("name", sorted(ALL))
def test_a_non_scene_is_an_input_error_naming_the_scene(name, bad):
    with pytest.raises(gp.InputError, match=r"^scene: expected a "):
        ALL[name](bad)


@pytest.mark.parametrize("name", sorted(PLANAR_FUNCTIONS))
def test_a_3d_scene_in_a_planar_function_points_to_arm3d(name):
    with pytest.raises(gp.InputError, match=r"scene: a 3-D scene \(Scene3D\): use gdnplan\.arm3d"):
        PLANAR_FUNCTIONS[name](SCENE3D)


@pytest.mark.parametrize("name", sorted(FUNCTIONS_3D))
def test_a_planar_scene_in_a_3d_function_points_to_the_planar_one(name):
    with pytest.raises(gp.InputError, match=r"scene: a planar scene \(Scene\): use gdnplan\."):
        FUNCTIONS_3D[name](PLANAR)


def test_the_pointers_name_the_matching_function():
    with pytest.raises(gp.InputError, match=r"use gdnplan\.arm3d\.signed_distance3d$"):
        gp.signed_distance(SCENE3D, Q3)
    with pytest.raises(gp.InputError, match=r"use gdnplan\.arm3d\.certify_path3d$"):
        gp.certify_path(SCENE3D, np.stack([Q3, Q3]))
    with pytest.raises(gp.InputError, match=r"use gdnplan\.certify_path$"):
        arm3d.certify_path3d(PLANAR, np.stack([Q2, Q2]))
    with pytest.raises(gp.InputError, match=r"make_scene\('b'\)"):
        gp.signed_distance("b", Q2)


@pytest.mark.parametrize(
    ("make", "message"),
    [
        (lambda: gp.Scene(None, ()), r"^robot: expected a Robot"),
        (lambda: gp.Scene("planar2", ()), r"^robot: expected a Robot"),
        (lambda: gp.Scene(ROBOT3D, ()), r"^robot: a 3-D robot \(Robot3D\): use gdnplan\.arm3d"),
        (lambda: gp.Scene(PLANAR.robot, 5), r"^obstacles: expected a list"),
        (lambda: gp.Scene(PLANAR.robot, "square"), r"^obstacles: expected a list"),
        (lambda: gp.Scene(PLANAR.robot, None), r"^obstacles: expected a list"),
        (lambda: arm3d.Scene3D(ROBOT3D, SCENE3D), r"^obstacles: got a Scene3D"),
        (lambda: arm3d.Scene3D(ROBOT3D, 5), r"^obstacles: expected a list"),
        (lambda: arm3d.Scene3D(PLANAR.robot, ()), r"^robot: .*gdnplan\.Scene"),
        (lambda: arm3d.Scene3D(None, ()), r"^robot: expected a Robot3D"),
    ],
)
def test_scene_constructors_check_their_arguments(make, message):
    with pytest.raises(gp.InputError, match=message):
        make()


def test_good_scenes_still_build():
    assert len(gp.Scene(PLANAR.robot, list(PLANAR.obstacles)).obstacles) == 1
    assert len(gp.Scene(PLANAR.robot, np.stack(PLANAR.obstacles)).obstacles) == 1
    assert len(arm3d.Scene3D(ROBOT3D, list(SCENE3D.obstacles)).obstacles) == 3


# ------------------------------------------------------------------ configurations
NUMERIC = [np.int8, np.int32, np.int64, np.uint8, np.uint16, np.float16, np.float32, np.float64]
OTHER = [np.bool_, np.complex64, np.complex128, np.dtype("U4"), np.dtype("S4"), np.object_]


@settings(max_examples=80, deadline=None)
@given(
    dtype=st.sampled_from(NUMERIC + OTHER),
    rows=st.integers(1, 4),
    data=st.data(),
)
def test_as_batch_accepts_real_kinds_only(dtype, rows, data):
    dtype = np.dtype(dtype)
    if dtype.kind == "O":
        q = np.array([[0.1, "x"]] * rows, dtype=object)
    else:
        elements = hnp.from_dtype(dtype, allow_nan=False, allow_infinity=False)
        q = data.draw(hnp.arrays(dtype, (rows, 2), elements=elements))
    if dtype.kind in "iuf":
        np.testing.assert_array_equal(as_batch(q, 2), q.astype(float))
        assert as_batch(q, 2).dtype == np.float64
    else:
        with pytest.raises(gp.InputError, match=r"^q: expected real numbers"):
            as_batch(q, 2)


SCALARS = st.one_of(
    st.integers(-5, 5),
    st.floats(-3, 3),
    st.booleans(),
    st.text(max_size=3),
    st.complex_numbers(max_magnitude=3, allow_nan=False),
    st.none(),
)


@settings(max_examples=120, deadline=None)
@given(values=st.lists(SCALARS, min_size=2, max_size=2))
def test_lists_of_non_numbers_are_refused_everywhere(values):
    real = all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in values)
    calls = [
        lambda: gp.signed_distance(PLANAR, values),
        lambda: gp.signed_distance_and_grad(PLANAR, [values]),
        lambda: PLANAR.robot.link_polygons(values),
    ]
    for call in calls:
        if real:
            call()
        else:
            with pytest.raises(gp.InputError, match=r"expected real numbers"):
                call()


@pytest.mark.parametrize(
    "q",
    [["0.1", "0.2"], np.array([0.1 + 1j, 0.2]), np.array([True, False]), [True, 0.5]],
    ids=["strings", "complex", "bool array", "bool in a list"],
)
def test_the_audits_configurations_are_refused_in_2d_and_3d(q):
    with pytest.raises(gp.InputError, match=r"^q: expected real numbers"):
        gp.signed_distance(PLANAR, q)
    q3 = np.concatenate([np.asarray(q, dtype=object), [0.0] * 4]).tolist()
    if isinstance(q, np.ndarray):
        q3 = np.concatenate([q, np.zeros(4, q.dtype)])
    with pytest.raises(gp.InputError, match=r"^q: expected real numbers"):
        arm3d.signed_distance3d(SCENE3D, q3)


# ------------------------------------------------------------------ seeds
BAD_SEEDS = [-3, True, 1.5, "1", [1, -1], [], np.bool_(True)]


@pytest.mark.parametrize("seed", BAD_SEEDS, ids=repr)
def test_bad_seeds_are_input_errors(seed):
    with pytest.raises(gp.InputError, match=r"^seed: expected None, an integer"):
        PLANAR.robot.sample(2, seed=seed)
    with pytest.raises(gp.InputError, match=r"^seed: expected None, an integer"):
        arm3d.random_boxes(ROBOT3D, 2, seed=seed)
    with pytest.raises(gp.InputError, match=r"^seed: expected None, an integer"):
        workspace_radius(ROBOT3D, 4, seed=seed)


@pytest.mark.parametrize("seed", [0, 7, np.int64(3), [1, 2], None], ids=repr)
def test_good_seeds_still_sample(seed):
    q = PLANAR.robot.sample(3, seed=seed)
    assert q.shape == (3, 2) and np.all(PLANAR.robot.within_limits(q))
    if seed is not None:
        np.testing.assert_array_equal(q, PLANAR.robot.sample(3, seed=seed))


# ------------------------------------------------------------------ polygons
@pytest.mark.parametrize(
    "poly",
    [
        [[0, 0], [1, 1], [2, 2]],
        [[0, 0], [2, 0], [1, 0]],
        [[0, 0], [1, 0], [3, 0], [2, 0]],
        [[5.0, 5.0], [5.5, 5.25], [7.0, 6.0]],
    ],
)
def test_a_collinear_polygon_has_zero_area(poly):
    with pytest.raises(gp.InputError, match=r"^obstacles\[0\]: the polygon has zero area"):
        as_polygon(poly, "obstacles[0]")
    with pytest.raises(gp.InputError, match=r"zero area \(collinear vertices\)"):
        gp.Scene(PLANAR.robot, (poly,))


def test_a_bowtie_still_intersects_itself():
    with pytest.raises(gp.InputError, match="intersects itself"):
        as_polygon([[0, 0], [1, 1], [1, 0], [0, 1]])
    assert as_polygon([[0, 0], [1, 0], [0, 1e-6]]).shape == (3, 2)  # thin is not flat


@settings(max_examples=40, deadline=None)
@given(mask=hnp.arrays(np.bool_, (3, 2)), grad=st.booleans())
def test_masked_entries_and_grad_tensors_are_refused_not_read(mask, grad):
    """A masked entry is no joint angle (numpy would read the hidden value); a tensor that
    requires grad names the fix (torch cannot hand it to numpy)."""
    import torch

    data = np.full((3, 2), 0.3)
    masked = np.ma.masked_array(data, mask=mask)
    if mask.any():
        with pytest.raises(gp.InputError, match=r"^q: masked entries"):
            gp.signed_distance(PLANAR, masked)
    else:
        np.testing.assert_array_equal(as_batch(masked, 2), data)
    tensor = torch.tensor(data, requires_grad=grad)
    if grad:
        with pytest.raises(gp.InputError, match=r"q\.detach\(\)"):
            gp.signed_distance_and_grad(PLANAR, tensor)
    else:
        np.testing.assert_array_equal(as_batch(tensor, 2), data)


def _circle(cx: float, cy: float, n: int, r: float = 0.03) -> np.ndarray:
    t = np.linspace(0, 2 * np.pi, n, endpoint=False)
    return np.c_[cx + r * np.cos(t), cy + r * np.sin(t)]


def test_a_scene_past_the_vertex_limit_is_refused_at_the_obstacle_that_passes_it():
    """500 polygons of 2 000 vertices were accepted, then each distance call took 14 s."""
    from gdnplan.scene_checks import MAX_SCENE_VERTICES

    scene = gp.make_scene("a")
    circles = [_circle(1.5 + 0.1 * (i % 30), 1.5 + 0.1 * (i // 30), 2000) for i in range(500)]
    k = MAX_SCENE_VERTICES // 2000
    with pytest.raises(
        gp.InputError, match=rf"^obstacles: more than 20000 vertices by obstacles\[{k}\]"
    ):
        scene.with_obstacles(circles)
    assert len(scene.with_obstacles(circles[:k]).obstacles) == k


def test_a_scene_past_the_part_limit_stops_at_the_first_obstacle_past_it():
    """The parts of every obstacle were computed before the count (1 000 stars: minutes)."""
    t = np.linspace(0, 2 * np.pi, 2000, endpoint=False)
    r = np.where(np.arange(2000) % 2 == 0, 0.05, 0.02)
    star = np.c_[1.5 + r * np.cos(t), 1.5 + r * np.sin(t)]
    with pytest.raises(
        gp.InputError, match=r"^obstacles: more than 500 convex parts by obstacles\[0\]"
    ):
        gp.make_scene("a").with_obstacles([star] * 10)
