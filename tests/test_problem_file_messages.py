"""Problem-file values far out of range are refused with messages naming the real problem,
computed without overflow: a 3-D quaternion that is no rotation, a planar goal position beyond
the robot's reach."""

from __future__ import annotations

import math
import warnings
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from gdnplan.errors import GdnplanError, InfeasibleProblemError, ProblemFileError
from gdnplan.trajopt import Problem

SQUARE = Path(__file__).parent.parent / "problems" / "planar2_square.toml"
FREE3D = """
[robot]
name = "ur5e"
{held}

[scene3d]
[[scene3d.obstacles]]
type = "box"
size = [0.1, 0.1, 0.1]
position = [0.0, 0.8, 0.3]
{obstacle_rotation}

[start]
q = [-0.6, -1.2, 1.2, -1.5, -1.57, 0.0]

[goal]
{goal}
"""
GOAL_Q = "q = [0.6, -1.2, 1.2, -1.5, -1.57, 0.0]"
HELD = """[robot.held]
type = "box"
size = [0.03, 0.03, 0.25]
position = [0.0, 0.0, 0.12]
quaternion = {}"""


def write(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "p.toml"
    path.write_text(text, encoding="utf-8")
    return path


def toml_number(x: float) -> str:
    return "nan" if math.isnan(x) else ("inf" if x == math.inf else repr(x))


@pytest.mark.parametrize(
    "quat, words",
    [
        ([1e300, 1e300, 0.0, 0.0], "not near 1"),
        ([2e3, 0.0, 0.0, 0.0], "not near 1"),
        ([0.0, 0.0, 0.0, 0.0], "zero length"),
        ([math.nan, 0.0, 0.0, 1.0], "not finite"),
        ([math.inf, 0.0, 0.0, 1.0], "not finite"),
    ],
)
@pytest.mark.parametrize("where", ["goal", "obstacle", "held"])
def test_a_bad_quaternion_is_named_as_one(tmp_path, quat, words, where):
    text = "[" + ", ".join(toml_number(x) for x in quat) + "]"
    parts = {"held": "", "obstacle_rotation": "", "goal": GOAL_Q}
    if where == "goal":
        parts["goal"] = f"pose = {{ position = [0.3, 0.3, 0.4], quaternion = {text} }}"
        field = "[goal] pose quaternion"
    elif where == "obstacle":
        parts["obstacle_rotation"] = f"quaternion = {text}"
        field = "[[scene3d.obstacles]] 0 quaternion"
    else:
        parts["held"] = HELD.format(text)
        field = "quaternion"
    path = write(tmp_path, FREE3D.format(**parts))
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no overflow RuntimeWarning on the way
        with pytest.raises(ProblemFileError) as info:
            Problem.from_toml(path)
    message = str(info.value)
    assert field in message and words in message, message
    assert "1000 m" not in message  # not the coordinates' message


def test_an_unnormalised_quaternion_is_still_accepted(tmp_path):
    path = write(
        tmp_path, FREE3D.format(held="", obstacle_rotation="quaternion = [0, 0, 2, 2]", goal=GOAL_Q)
    )
    assert Problem.from_toml(path).scene.obstacles


@settings(max_examples=40, deadline=None)
@given(x=st.floats(allow_nan=False, allow_infinity=False).filter(lambda v: abs(v) > 5.0))
def test_a_far_goal_position_is_out_of_reach_without_overflow(tmp_path_factory, x):
    text = SQUARE.read_text().replace("q = [1.448, -2.722]", f"position = [{x!r}, 0.5]")
    path = tmp_path_factory.mktemp("far") / "p.toml"
    path.write_text(text, encoding="utf-8")
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # the overflow RuntimeWarning of norm([1e300, …])
        with pytest.raises(GdnplanError) as info:
            Problem.from_toml(path)
    message = str(info.value)
    assert isinstance(info.value, InfeasibleProblemError) and "out of reach" in message
    assert "inf m" not in message and "the tip reaches" in message


@pytest.mark.parametrize(
    ("table", "typo", "meant"),
    [("options", "margn", "margin"), ("seed", "rrt_stepp", "rrt_step"), ("goal", "qq", "q")],
)
def test_an_unknown_key_names_the_closest_allowed_one(tmp_path, table, typo, meant):
    path = tmp_path / "p.toml"
    text = SQUARE.read_text()
    header = f"[{table}]\n"
    text = text.replace(header, f"{header}{typo} = 1\n") if header in text else text
    path.write_text(text if header in text else f"{text}\n{header}{typo} = 1\n")
    with pytest.raises(ProblemFileError, match=rf"\['{typo}'\] \(did you mean '{meant}'\?\)"):
        Problem.from_toml(path)


def test_a_byte_order_mark_is_read(tmp_path):
    """A problem file saved with a UTF-8 byte-order mark (Windows editors) was refused as
    'malformed TOML: Invalid statement (at line 1, column 1)'."""
    path = tmp_path / "bom.toml"
    path.write_bytes(b"\xef\xbb\xbf" + SQUARE.read_bytes())
    assert Problem.from_toml(path).start.tolist() == Problem.from_toml(SQUARE).start.tolist()


@pytest.mark.parametrize(
    ("cfg", "base_dir", "message"),
    [
        (None, None, r"^problem: expected a table of tables .*got NoneType"),  # TypeError
        ([], None, r"^problem: expected a table of tables .*got list"),  # "[start]: missing"
        ({}, 3, r"^base_dir: expected a folder path, got int"),
    ],
)
def test_from_config_of_no_mapping_or_a_bad_base_dir(cfg, base_dir, message):
    with pytest.raises(ProblemFileError, match=message):
        Problem.from_config(cfg, base_dir=base_dir)
