"""Every ``<collision>`` of a user URDF reaches the collision model or the file is refused
(planar and 3-D loader alike): malformed numbers, shapes, origins and mesh files, joint limits,
the per-link collision count, and the continuous joint's default velocity."""

from __future__ import annotations

import re
import shutil
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import gdnplan as gp
from gdnplan.arm3d import robot3d_from_urdf
from gdnplan.errors import GdnplanError, InputError
from gdnplan.timing import urdf_velocity
from gdnplan.urdf_robot import CONTINUOUS_VELOCITY, RobotSpec, robot_from_urdf

ROOT = Path(__file__).resolve().parent.parent
EXAMPLE = ROOT / "examples" / "three_link_arm.urdf"
TEXT = EXAMPLE.read_text()
JOINTS = ("shoulder", "elbow", "wrist")
BOX = '<box size="0.4 0.06 0.05"/>'
HAND_ORIGIN = 'rpy="0 1.5707963267948966 0"'


def mutated(folder: Path, old: str, new: str, name: str = "arm.urdf") -> Path:
    """The example URDF with ``old`` replaced by ``new``, written into ``folder``."""
    assert old in TEXT, old
    path = folder / name
    path.write_text(TEXT.replace(old, new))
    return path


def load(path: Path, kind: str) -> int:
    """Number of collision shapes of the planar or 3-D robot of the URDF ``path``."""
    if kind == "planar":
        spec = RobotSpec(urdf=path, planning_joints=JOINTS, locked={"tool_roll": 1.5})
        return len(robot_from_urdf("user_arm", spec).polygons)
    return len(robot3d_from_urdf(path).shapes)


def xml_collisions(path: Path) -> int:
    root = ET.fromstring(path.read_bytes())
    return sum(len(link.findall("collision")) for link in root.findall("link"))


def refused(path: Path, kind: str, match: str, capfd=None) -> str:
    """Load and expect one-line InputError matching ``match``; nothing printed on stderr."""
    with pytest.raises(InputError, match=match) as info:
        load(path, kind)
    message = str(info.value)
    assert "\n" not in message and path.name in message
    if capfd is not None:
        assert capfd.readouterr().err == ""
    return message


KINDS = pytest.mark.parametrize("kind", ["planar", "3d"])

# (old, new, link named, attribute named): each one was dropped silently by urdfdom
MALFORMED = [
    (BOX, '<box size="nan 0.06 0.05"/>', "forearm", "box size"),
    (BOX, '<box size="abc 0.06 0.05"/>', "forearm", "box size"),
    (BOX, '<box size="inf 0.06 0.05"/>', "forearm", "box size"),
    (BOX, '<box size="1e999 0.06 0.05"/>', "forearm", "box size"),
    (BOX, '<box size="0.4 0.06"/>', "forearm", "box size"),
    (BOX, '<box size="0.4 0.06 0.05 0.1"/>', "forearm", "box size"),
    (BOX, '<box size="-0.4 0.06 0.05"/>', "forearm", "box size"),
    (BOX, '<box size="0 0.06 0.05"/>', "forearm", "box size"),
    (BOX, '<box size="0.4 0.06 5000"/>', "forearm", "box size"),
    (BOX, "<box/>", "forearm", "box size"),
    (BOX, "<sphere/>", "forearm", "sphere radius"),
    (BOX, '<sphere radius="0.1 0.2"/>', "forearm", "sphere radius"),
    (BOX, '<sphere radius="1e-400"/>', "forearm", "sphere radius"),
    (BOX, '<cylinder radius="0.1"/>', "forearm", "cylinder length"),
    (BOX, '<capsule radius="0.03" length="0.3"/>', "forearm", "capsule"),
    (BOX, "<foo/>", "forearm", "foo"),
    (BOX, "<mesh/>", "forearm", "mesh"),
    (BOX, '<mesh filename="  "/>', "forearm", "mesh"),
    (BOX, BOX + '<sphere radius="0.1"/>', "forearm", "geometry"),
    (f"<geometry>{BOX}</geometry>", "<geometry/>", "forearm", "geometry"),
    (f"<geometry>{BOX}</geometry>", "", "forearm", "geometry"),
    (BOX, BOX + '</geometry><geometry><sphere radius="1"/>', "forearm", "geometry"),
    ('radius="0.03"', 'radius="abc"', "hand", "cylinder radius"),
    ('length="0.15"', 'length=""', "hand", "cylinder length"),
    (HAND_ORIGIN, 'rpy="nan 0 0"', "hand", "rpy"),
    (HAND_ORIGIN, 'rpy="0 1.57"', "hand", "rpy"),
    (HAND_ORIGIN, 'rpy="0 1e9 0"', "hand", "rpy"),
    (HAND_ORIGIN, 'quat_xyzw="0 0 0 1"', "hand", "quat_xyzw"),
    ('<origin xyz="0.2 0 0"/>', '<origin xyz="nan 0 0"/>', "forearm", "xyz"),
    ('<origin xyz="0.2 0 0"/>', '<origin xyz="0.2 0 0"/><origin/>', "forearm", "origin"),
]


@KINDS
@pytest.mark.parametrize(("old", "new", "link", "attribute"), MALFORMED)
def test_a_malformed_collision_is_refused_naming_link_and_attribute(
    tmp_path, capfd, kind, old, new, link, attribute
):
    path = mutated(tmp_path, old, new)
    message = refused(path, kind, f"link '{link}'", capfd)
    assert attribute in message


@KINDS
@pytest.mark.parametrize(
    ("old", "new", "match"),
    [
        ('<origin xyz="0.5 0 0"/>', '<origin xyz="0.5 0 0" rpy="0 nan 0"/>', "joint 'elbow'"),
        ('<origin xyz="0.5 0 0"/>', '<origin xyz="0.5 0 0" quat_xyzw="0 0 0 1"/>', "elbow"),
        ('lower="-2.6" upper="2.6"', 'lower="-1e300" upper="1e300"', "joint 'elbow'.*±1000"),
        ('lower="-2.6" upper="2.6"', 'lower="2.6" upper="-2.6"', "joint 'elbow'.*lower > upper"),
        ('lower="-2.6" upper="2.6"', 'lower="1" upper="1"', "joint 'elbow'.*upper − lower ≥"),
        ('lower="-2.6" upper="2.6"', 'lower="0" upper="1e-300"', "joint 'elbow'.*upper − lower"),
        ('lower="-2.6" upper="2.6"', 'lower="-2.6" upper="nan"', "elbow|limit|double"),
        ('lower="-1.6" upper="1.6"', 'lower="1.6" upper="-1.6"', "joint 'tool_roll'"),
    ],
)
def test_bad_joint_origins_and_limits_are_refused_naming_the_joint(
    tmp_path, capfd, kind, old, new, match
):
    refused(mutated(tmp_path, old, new), kind, match, capfd)


@pytest.mark.parametrize(
    ("field", "value"),
    [
        ("joints", "shoulder"),
        ("joints", ["shoulder", 3]),
        ("locked", [("tool_roll", 0.1)]),
        ("locked", {1: 0.1}),
        ("package_dirs", "/tmp"),
        ("package_dirs", [None]),
        ("name", 123),
        ("name", " "),
    ],
)
def test_robot3d_arguments_of_the_wrong_kind_are_refused_naming_them(field, value):
    """A bare string where a list is meant iterated as its characters ('j0' → 'j', '0'), a
    list of pairs where a table is meant raised AttributeError, a number was a name."""
    with pytest.raises(InputError, match=rf"^{field}: expected"):
        robot3d_from_urdf(EXAMPLE, **{field: value})


def test_a_locked_joint_may_have_equal_limits(tmp_path):
    path = mutated(tmp_path, 'lower="-1.6" upper="1.6"', 'lower="0.5" upper="0.5"')
    spec = RobotSpec(urdf=path, planning_joints=JOINTS, locked={"tool_roll": 0.5})
    assert len(robot_from_urdf("user_arm", spec).polygons) == 5


# -------------------------------------------------------------------- mesh files
def cube_obj(path: Path, bad: str = "1 1 1") -> Path:
    corners = [f"{x} {y} {z}" for x in (0, 1) for y in (0, 1) for z in (0, 1)]
    corners[-1] = bad
    faces = ["1 2 3", "2 3 4", "5 6 7", "6 7 8", "1 2 5", "2 5 6", "3 4 7", "4 7 8"]
    path.write_text("".join(f"v {c}\n" for c in corners) + "".join(f"f {f}\n" for f in faces))
    return path


def mesh_case(folder: Path, case: str) -> tuple[str, str]:
    """(filename attribute, expected message part) of a broken mesh ``case``."""
    if case == "text":
        (folder / "notes.stl").write_text("no mesh here\n" * 20)
        return "notes.stl", "not a mesh file"
    if case == "directory":
        (folder / "meshes").mkdir()
        return "meshes", "is a directory"
    if case == "device":
        return "/dev/null", "not a regular file"
    if case == "missing":
        return "nowhere.stl", "does not exist"
    if case == "outside":
        return "../../x", "does not exist"
    if case == "scheme":
        return "http://example.com/a.stl", "scheme"
    if case == "nan":
        return cube_obj(folder / "nan.obj", "1 1 nan").name, "NaN or infinite"
    if case == "far":
        return cube_obj(folder / "far.obj", "1 1 5000").name, "beyond 1000 m"
    if case == "empty_stl":  # a valid header, no facet: assimp's reason is passed on
        (folder / "empty.stl").write_bytes(bytes(80) + (0).to_bytes(4, "little"))
        return "empty.stl", "(assimp: STL: file is empty"
    assert case == "empty"
    (folder / "empty.obj").write_text("# nothing\n")
    return "empty.obj", "mesh"


@KINDS
@pytest.mark.parametrize(
    "case",
    [
        "text",
        "directory",
        "device",
        "missing",
        "outside",
        "scheme",
        "nan",
        "far",
        "empty",
        "empty_stl",
    ],
)
def test_a_bad_mesh_file_is_named_with_its_link_and_path(tmp_path, capfd, kind, case):
    filename, what = mesh_case(tmp_path, case)
    path = mutated(tmp_path, BOX, f'<mesh filename="{filename}"/>')
    message = refused(path, kind, "link 'forearm'", capfd)  # no "eigen: ..." noise either
    assert what in message and filename in message


@KINDS
@pytest.mark.parametrize("scale", ["nan 1 1", "0 1 1", "1 1", "1e9 1 1"])
def test_a_bad_mesh_scale_is_refused(tmp_path, capfd, kind, scale):
    cube_obj(tmp_path / "cube.obj")
    path = mutated(tmp_path, BOX, f'<mesh filename="cube.obj" scale="{scale}"/>')
    assert "mesh scale" in refused(path, kind, "link 'forearm'", capfd)


@KINDS
def test_a_good_mesh_and_a_rotated_sphere_load(tmp_path, kind):
    cube_obj(tmp_path / "cube.obj")
    path = mutated(tmp_path, BOX, '<mesh filename="cube.obj" scale="0.4 0.06 0.05"/>')
    assert load(path, kind) == xml_collisions(path) == 5
    sphere = '<collision><origin rpy="1 2 3"/><geometry><sphere radius="0.05"/></geometry>'
    path = mutated(tmp_path, f"{BOX}</geometry>", f"{BOX}</geometry></collision>{sphere}")
    assert load(path, kind) == xml_collisions(path) == 6  # a sphere's rotation is harmless


# -------------------------------------------------------------------- counts and visuals
@KINDS
def test_the_collision_count_refuses_what_urdfdom_drops_even_unchecked(tmp_path, kind, monkeypatch):
    """The per-link count is the backstop: without the XML checks urdfdom drops the nan box."""
    import gdnplan.urdf_robot.load as load_module

    monkeypatch.setattr(load_module, "check_urdf_xml", lambda root, path: None)
    path = mutated(tmp_path, BOX, '<box size="nan 0.06 0.05"/>')
    message = refused(path, kind, r"link 'forearm' has 1 <collision> element\(s\) but 0")
    assert "urdfdom" in message


@KINDS
def test_visual_only_links_are_fine_and_malformed_visuals_never_drop_a_collision(tmp_path, kind):
    visual = '<visual><geometry><box size="0.1 0.1 0.1"/></geometry></visual>'
    path = mutated(tmp_path, '<link name="tip"/>', f'<link name="tip">{visual}</link>')
    assert load(path, kind) == xml_collisions(path) == 5
    bad = visual.replace("0.1 0.1 0.1", "nan 1")
    path = mutated(tmp_path, '<link name="forearm">', f'<link name="forearm">{bad}')
    try:
        assert load(path, kind) == xml_collisions(path)
    except InputError as e:
        assert "\n" not in str(e)


# -------------------------------------------------------------------- continuous joints
@KINDS
def test_a_continuous_planning_joint_without_limit_gets_the_default_velocity(tmp_path, kind):
    if kind == "planar":
        robot = robot_from_urdf("user_arm", RobotSpec(EXAMPLE, JOINTS, {"tool_roll": 1.5}))
    else:
        robot = robot3d_from_urdf(EXAMPLE)
    wrist = robot.joint_names.index("wrist")
    assert robot.model.velocityLimit[wrist] == CONTINUOUS_VELOCITY
    assert np.isinf(robot.model.effortLimit[wrist])
    v = urdf_velocity(robot)  # timing works: every limit finite and positive
    assert v[wrist] == CONTINUOUS_VELOCITY and v[0] == 2.0
    given_limit = '<limit effort="3" velocity="4"/></joint>\n  <link name="hand">'
    path = mutated(tmp_path, '</joint>\n  <link name="hand">', given_limit)
    robot = (
        robot3d_from_urdf(path)
        if kind == "3d"
        else robot_from_urdf("user_arm", RobotSpec(path, JOINTS, {"tool_roll": 1.5}))
    )
    assert robot.model.velocityLimit[wrist] == 4.0


# -------------------------------------------------------------------- the audit's plan
def test_the_nan_box_urdf_can_no_longer_give_a_certified_plan(tmp_path):
    path = mutated(tmp_path, BOX, '<box size="nan 0.06 0.05"/>', name="three_link_arm.urdf")
    shutil.copy(EXAMPLE.with_suffix(".toml"), tmp_path / "three_link_arm.toml")
    with pytest.raises(InputError, match=r"link 'forearm'.*box size"):
        load(path, "planar")
    with pytest.raises(GdnplanError, match=r"link 'forearm'.*box size") as info:
        gp.Problem.from_toml(tmp_path / "three_link_arm.toml")
    assert "\n" not in str(info.value)


# -------------------------------------------------------------------- property
COLLISION_NUMBERS = re.compile(r'(size|radius|length|xyz|rpy)="([^"]*)"')
TOKENS = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True).map(repr),
    st.floats(-2.0, 2.0).map(lambda x: f"{x:.3g}"),
    st.sampled_from(["", "abc", "nan", "-inf", "1e999", "1e-400", "0", "1,2", "0x10", ".5"]),
)


def collision_spans() -> list[tuple[int, int]]:
    """(start, end) of every numeric attribute value inside the example's <collision>s."""
    spans = []
    for block in re.finditer(r"<collision>.*?</collision>", TEXT, re.S):
        for m in COLLISION_NUMBERS.finditer(block.group(0)):
            spans.append((block.start() + m.start(2), block.start() + m.end(2)))
    return spans


SPANS = collision_spans()


@settings(
    max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(
    which=st.integers(0, len(SPANS) - 1),
    slot=st.integers(0, 3),
    token=TOKENS,
    kind=st.sampled_from(["planar", "3d"]),
)
def test_any_mutated_collision_number_loads_every_collision_or_is_refused(
    tmp_path, which, slot, token, kind
):
    start, end = SPANS[which]
    words = TEXT[start:end].split(" ")
    if slot < len(words):
        words[slot] = token
    else:
        words.append(token)  # one number too many (or a trailing empty word)
    path = tmp_path / "mutant.urdf"
    path.write_text(TEXT[:start] + " ".join(words) + TEXT[end:])
    try:
        shapes = load(path, kind)
    except InputError as e:
        assert "\n" not in str(e) and "mutant.urdf" in str(e)
        return
    assert shapes == xml_collisions(path) == 5


@pytest.mark.parametrize(("bad", "match"), [("1 1 nan", "NaN or infinite"), ("1 1 5000", "1000 m")])
def test_a_problem_file_mesh_with_a_bad_vertex_is_refused_quietly(tmp_path, capfd, bad, match):
    from gdnplan.arm3d.shape_file3d import posed_shape
    from gdnplan.errors import ProblemFileError

    cube_obj(tmp_path / "rock.obj", bad)
    table = {"type": "mesh", "file": "rock.obj", "position": [0.5, 0.0, 0.2]}
    with pytest.raises(ProblemFileError, match=f"rock.obj.*{match}") as info:
        posed_shape(table, "[[scene3d.obstacles]] 0", tmp_path, "mesh0")
    assert "\n" not in str(info.value) and capfd.readouterr().err == ""
    cube_obj(tmp_path / "cube.obj")
    good = posed_shape({**table, "file": "cube.obj"}, "[[scene3d.obstacles]] 0", tmp_path, "m")
    assert good.name == "m"


@KINDS
def test_a_urdf_with_visuals_only_is_refused_saying_visuals_are_not_read(tmp_path, kind):
    text = re.sub(r"<collision>.*?</collision>", "", TEXT, flags=re.S)
    visual = '<visual><geometry><box size="0.1 0.1 0.1"/></geometry></visual>'
    path = tmp_path / "visual_only.urdf"
    path.write_text(text.replace('<link name="forearm">', f'<link name="forearm">{visual}'))
    assert xml_collisions(path) == 0
    refused(path, kind, r"no collision geometry.*<visual> elements are not read")


# -------------------------------------------------------------------- mesh sizes
def big_stl(path: Path, triangles: int) -> Path:
    """A binary STL of ``triangles`` random triangles in a 0.1 m cube (real facets)."""
    rng = np.random.default_rng(0)
    rec = np.zeros(triangles, dtype=[("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")])
    rec["v"] = rng.random((triangles, 3, 3)) * 0.1
    path.write_bytes(bytes(80) + triangles.to_bytes(4, "little") + rec.tobytes())
    return path


def _never_read(monkeypatch) -> None:
    """Make any full read of a mesh file (coal's assimp loader) fail the test."""
    import coal

    def loader(*args, **kwargs):
        raise AssertionError("the mesh file was read whole before it was refused")

    monkeypatch.setattr(coal, "MeshLoader", loader)


@KINDS
def test_a_binary_stl_beyond_the_triangle_limit_is_refused_from_its_header(
    tmp_path, kind, monkeypatch
):
    """Audit: a URDF mesh of 500 000 triangles (1.5 M vertices) was parsed whole by assimp
    (seconds, hundreds of MB) before its vertex count was refused."""
    from gdnplan.urdf_robot.meshes import MAX_MESH_TRIANGLES

    big_stl(tmp_path / "big.stl", MAX_MESH_TRIANGLES + 1)
    path = mutated(tmp_path, BOX, '<mesh filename="big.stl"/>')
    _never_read(monkeypatch)
    message = refused(path, kind, "link 'forearm'")
    assert f"binary STL of {MAX_MESH_TRIANGLES + 1} triangles" in message and "big.stl" in message


@KINDS
@pytest.mark.parametrize("suffix", ["obj", "dae", "stl"])
def test_a_mesh_file_beyond_the_byte_limit_is_refused_before_reading(
    tmp_path, kind, monkeypatch, suffix
):
    from gdnplan.urdf_robot.meshes import MAX_MESH_BYTES

    mesh = tmp_path / f"big.{suffix}"
    with open(mesh, "wb") as f:  # sparse: the size alone matters
        f.write(b"solid x\n" if suffix == "stl" else b"v 0 0 0\n")
        f.truncate(MAX_MESH_BYTES + 1)
    path = mutated(tmp_path, BOX, f'<mesh filename="big.{suffix}"/>')
    _never_read(monkeypatch)
    assert f"more than {MAX_MESH_BYTES}" in refused(path, kind, "link 'forearm'")


def test_the_mesh_vertex_limit_is_the_hull_limit():
    from gdnplan.arm3d.shapes import MAX_HULL_POINTS
    from gdnplan.urdf_robot.meshes import MAX_MESH_VERTICES

    assert MAX_MESH_VERTICES == MAX_HULL_POINTS
