"""docs/problem_file.md against the parser.

The schema page lists every table's keys in markdown tables (a ``## `[table]` `` heading, or
``### `[robot]` with `name = "ur5e"` `` for one robot's or generator's options, then rows
``| `key` | type | default | unit | meaning | example | refused |``). These tests check that
the documented keys are exactly the keys the parser accepts (its own key constants and the
robot and scene factories' options), that each documented default is the parser's, that each
row's example line is accepted (and reaches the problem) and its refused line refused with an
error naming the key, and that every full TOML example on the page loads. A key added to the
parser without a row here fails them.
"""

from __future__ import annotations

import dataclasses
import inspect
import re
import shutil
import tomllib
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest
import tomli_w

import gdnplan as gp
from gdnplan.errors import SCHEMA_DOC
from gdnplan.limits import IPOPT_OPTIONS
from gdnplan.registry import ROBOTS, SCENES
from gdnplan.robot import robot_names, robot_options
from gdnplan.robot_file import DEFAULT_PLANE, URDF_KEYS
from gdnplan.scene import OBSTACLE_KEYS, ROBOT_KEYS, SCENE_KEYS, scene_names, scene_options
from gdnplan.trajopt import (
    CONFIG_KEYS,
    CONFIG_TABLES,
    GOAL_KEYS,
    OLD_KEYS,
    OPTION_KEYS,
    SOLVER_KEYS,
    START_KEYS,
    TOP_KEYS,
    read_problem_file,
)
from gdnplan.urdf_robot import RobotSpec

ROOT = Path(__file__).resolve().parent.parent
DOC = ROOT / SCHEMA_DOC
HEADING = re.compile(
    r'^#{2,3} `(\[\[?[a-z_.]+\]\]?)`(?: with `(name|generator) = "(\w+)"`| with `(urdf)`)?\s*$'
)
COLUMNS = ["key", "type", "default", "unit", "meaning", "example", "refused"]
BASE = ROOT / "problems" / "planar2_square.toml"  # the context of every example ...
BASES = {  # ... but these sections'
    ("robot", "ur5e"): ROOT / "problems" / "fetch_bring_out.toml",
    ("scene", "fetch"): ROOT / "problems" / "fetch_bring_out.toml",
    ("robot", "urdf"): ROOT / "examples" / "three_link_arm.toml",  # its URDF is copied beside
}
USER_URDF = ROOT / "examples" / "three_link_arm.urdf"
Section = tuple[str, str | None]  # (table, robot or generator name the rows belong to)


@dataclass(frozen=True)
class Row:
    section: Section
    key: str
    type: str
    default: str
    unit: str
    meaning: str
    example: str
    refused: str

    @property
    def id(self) -> str:
        table, name = self.section
        return f"{table}{f'({name})' if name else ''}.{self.key}"


def doc_rows() -> list[Row]:
    """Every key row of the schema page, with the section it is documented in."""
    rows, section = [], None
    for number, line in enumerate(DOC.read_text(encoding="utf-8").splitlines(), 1):
        if line.startswith("#"):
            m = HEADING.match(line)
            section = (m[1].strip("[]"), m[3] or m[4]) if m else None
        elif section is not None and line.startswith("| `"):
            cells = [c.strip() for c in line.strip().strip("|").split("|")]
            assert len(cells) == len(COLUMNS), f"{DOC.name}:{number}: expected {COLUMNS}"
            key = re.fullmatch(r"`(\w+)`", cells[0])
            assert key, f"{DOC.name}:{number}: the key cell must be `key`"
            rows.append(Row(section, key[1], *cells[1:]))
    return rows


def parser_keys() -> dict[Section, set[str]]:
    """The keys the parser accepts, per section (sections without keys left out)."""
    keys = {
        ("robot", None): set(ROBOT_KEYS),
        ("scene", None): set(SCENE_KEYS),
        ("obstacles", None): set(OBSTACLE_KEYS),
        ("start", None): set(START_KEYS),
        ("goal", None): set(GOAL_KEYS),
        ("options", None): set(OPTION_KEYS),
        ("ipopt.options", None): set(IPOPT_OPTIONS),
    }
    keys |= {(table, None): set(names) for table, names in CONFIG_KEYS.items()}
    keys |= {("robot", n): robot_options(n) for n in robot_names() if robot_options(n)}
    keys[("robot", "urdf")] = set(URDF_KEYS)
    keys |= {("scene", n): scene_options(n) for n in scene_names() if scene_options(n)}
    return keys


ROWS = doc_rows()


def by_section() -> dict[Section, set[str]]:
    out: dict[Section, set[str]] = {}
    for row in ROWS:
        assert row.key not in out.get(row.section, set()), f"{row.id} documented twice"
        out.setdefault(row.section, set()).add(row.key)
    return out


def test_documented_keys_are_the_accepted_keys():
    documented, accepted = by_section(), parser_keys()
    assert set(documented) == set(accepted), "sections: documented vs accepted"
    for section in accepted:
        assert documented[section] == accepted[section], section
    tables = {table for table, _ in documented if "." not in table}
    assert tables == set(TOP_KEYS) - {"solver"}  # the deprecated table: its own test below


def test_old_solver_table_is_documented_key_by_key():
    text = DOC.read_text(encoding="utf-8").split("## The old `[solver]` table")[1]
    rows = dict(re.findall(r"^\| (\w+) \| (.+?) \|$", text, re.M))
    assert set(rows) == set(SOLVER_KEYS) == set(OLD_KEYS)
    for key, home in OLD_KEYS.items():
        assert rows[key].startswith("removed" if home is None else f"[{home[0]}] {home[1]}"), key


def test_every_robot_and_generator_is_named():
    types = {(row.section[0], row.key): row.type for row in ROWS}
    for name in robot_names():
        assert f"`{name}`" in types[("robot", "name")], name
    for name in scene_names():
        assert f"`{name}`" in types[("scene", "generator")], name


def parser_default(row: Row):
    """The parser's default of a key (inspect.Parameter.empty where it has none to compare)."""
    table, name = row.section
    if table == "options":
        return {f.name: f.default for f in dataclasses.fields(gp.Problem)}[row.key]
    if table in CONFIG_TABLES:
        default = getattr(CONFIG_TABLES[table](), row.key)
        return list(default) if isinstance(default, tuple) else default
    if (table, name) == ("robot", "urdf"):
        spec = {f.name: f.default for f in dataclasses.fields(RobotSpec)}
        defaults = {"plane": [list(axis) for axis in DEFAULT_PLANE]}
        defaults |= {k: spec[k] for k in ("max_vertices", "base_radius")}
        return defaults.get(row.key, inspect.Parameter.empty)
    factory = None
    if table == "robot" and name is not None:
        factory = ROBOTS.get(name)
    elif table == "scene" and name is not None:
        factory = SCENES.get(name)
    elif (table, row.key) == ("scene", "seed"):
        factory = gp.make_scene
    if factory is None:
        return inspect.Parameter.empty
    return inspect.signature(factory).parameters[row.key].default


@pytest.mark.parametrize("row", ROWS, ids=lambda r: r.id)
def test_documented_default_is_the_parsers(row):
    default = parser_default(row)
    if default is inspect.Parameter.empty:  # required, or set outside the parser (Ipopt's)
        return
    literal = re.fullmatch(r"`([^`]+)`", row.default)
    if default is None:  # automatic or the robot's: no TOML value, described in words
        assert literal is None, f"{row.id}: the default is automatic, not {row.default}"
    else:
        assert literal, f"{row.id}: expected the default as `value`, got {row.default!r}"
        assert tomllib.loads(f"x = {literal[1]}")["x"] == default, row.id


def snippet(cell: str, row: Row) -> dict:
    """The ``key = value`` line of an example or refused cell, parsed."""
    line = re.fullmatch(r"`([^`]+)`", cell)
    assert line, f"{row.id}: expected `{row.key} = value`, got {cell!r}"
    value = tomllib.loads(line[1])
    assert list(value) == [row.key], f"{row.id}: the line sets {list(value)}"
    return value


def load_with(row: Row, line: dict, tmp_path: Path) -> gp.Problem:
    """The section's base problem with ``line`` set in the row's table, through a file."""
    cfg = read_problem_file(BASES.get(row.section, BASE))
    table = row.section[0]
    if table == "obstacles":
        cfg.setdefault("obstacles", []).append(line)
    elif table == "goal":  # exactly one of q, position
        cfg["goal"] = line
    elif table == "ipopt.options":
        cfg.setdefault("ipopt", {}).setdefault("options", {}).update(line)
    else:
        cfg.setdefault(table, {}).update(line)
    path = tmp_path / "problem.toml"
    path.write_text(tomli_w.dumps(cfg), encoding="utf-8")
    if row.section == ("robot", "urdf"):
        shutil.copy(USER_URDF, tmp_path)
    return gp.Problem.from_toml(path)


UNSEEN = {("scene", "max_tries")}  # keys that leave no trace in the loaded problem


def reached(row: Row, problem: gp.Problem):
    """Where the row's key ends up in the loaded problem."""
    table, key = row.section[0], row.key
    scene = problem.scene
    if table == "robot":
        return scene.robot.name if key == "name" else scene.robot.info[key]
    if table == "scene":
        return (
            {"generator": scene.name, "seed": scene.seed}[key]
            if key in SCENE_KEYS
            else (scene.info[key])
        )
    return {
        "options": lambda: getattr(problem, key),
        "seed": lambda: getattr(problem.solver.seed, key),
        "refine": lambda: getattr(problem.solver.refine, key),
        "ipopt": lambda: getattr(problem.solver.optimizer, key),
        "adam": lambda: getattr(problem.solver.optimizer, key),
        "ipopt.options": lambda: problem.solver.optimizer.options[key],
        "start": lambda: problem.start.tolist(),
        "goal": lambda: (problem.goal if key == "q" else problem.goal_position).tolist(),
        "obstacles": lambda: sorted(map(tuple, scene.obstacles[-1].tolist())),  # CCW, rotated
    }[table]()


@pytest.mark.parametrize("row", ROWS, ids=lambda r: r.id)
def test_example_is_accepted(row, tmp_path):
    line = snippet(row.example, row)
    problem = load_with(row, line, tmp_path)
    value = line[row.key]
    if (row.section[0], row.key) in UNSEEN or row.section == ("robot", "urdf"):
        return  # a URDF robot keeps no table of its keys: loading it is the check
    if row.section[0] == "obstacles":
        value = sorted(map(tuple, value))
    got = reached(row, problem)
    got = got.tolist() if isinstance(got, np.ndarray) else got
    got = list(got) if isinstance(got, tuple) else got
    assert got == value, f"{row.id}: {value!r} set, {got!r} loaded"


@pytest.mark.parametrize("row", ROWS, ids=lambda r: r.id)
def test_refused_is_refused_naming_the_key(row, tmp_path):
    line = snippet(row.refused, row)
    with pytest.raises((gp.ProblemFileError, gp.UnknownNameError)) as err:
        load_with(row, line, tmp_path)
    message = str(err.value)
    assert "\n" not in message
    assert row.key in message or row.section[0].split(".")[0] in message, message


def toml_blocks() -> list[str]:
    return re.findall(r"```toml\n(.*?)```", DOC.read_text(encoding="utf-8"), re.S)


@pytest.mark.parametrize("index", range(len(toml_blocks())))
def test_full_examples_load(index, tmp_path):
    path = tmp_path / "example.toml"
    path.write_text(toml_blocks()[index], encoding="utf-8")
    problem = gp.Problem.from_toml(path)
    assert problem.scene.robot.dof == len(problem.start)


def test_schema_errors_point_to_the_page(tmp_path):
    assert DOC.is_file()
    cfg = read_problem_file(BASE)
    cfg["options"]["speed"] = 3
    path = tmp_path / "problem.toml"
    path.write_text(tomli_w.dumps(cfg), encoding="utf-8")
    with pytest.raises(gp.ProblemFileError, match=r"\['speed'\]") as err:
        gp.Problem.from_toml(path)
    assert str(err.value).endswith(f"(see {SCHEMA_DOC})")
    assert str(err.value).count(SCHEMA_DOC) == 1  # once, though re-raised with the file name
