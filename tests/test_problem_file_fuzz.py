"""A fuzzer of problem files: any text is a Problem or one GdnplanError, never another exception.

Mutations of a valid problem: fields replaced by values of any TOML type (huge, NaN, inf,
strings, booleans, nested arrays and tables), tables dropped or added, unknown keys, obstacles
of random vertices, and random bytes spliced into the text. Through the CLI (``show``, which
parses like ``plan`` without planning): exit 0 or 2, one ``error:`` line, no traceback.
"""

from __future__ import annotations

import math
import subprocess
import sys
import tomllib
from pathlib import Path

import tomli_w
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from gdnplan.errors import GdnplanError
from gdnplan.trajopt import Problem

BASE = tomllib.loads(
    (Path(__file__).parent.parent / "problems" / "planar2_square.toml").read_text()
)
ANSWER_TIMEOUT = 60.0  # s: a hang guard for the subprocess, not a performance bound

scalars = st.one_of(
    st.integers(-(2**63), 2**63 - 1),
    st.sampled_from([10**309, -(10**400)]),  # TOML ints past the float range (OverflowError)
    st.floats(allow_nan=True, allow_infinity=True),
    st.sampled_from([0, -1, 1, 3, 1e9, 1e300, -0.0, math.nan, math.inf, 0.02, 2.006]),
    st.text(max_size=8),
    st.booleans(),
)
values = st.recursive(
    scalars,
    lambda inner: st.one_of(
        st.lists(inner, max_size=5), st.dictionaries(st.text(max_size=6), inner, max_size=3)
    ),
    max_leaves=12,
)
vertex = st.lists(st.floats(-3, 3) | scalars, min_size=0, max_size=3)
obstacle = st.dictionaries(
    st.sampled_from(["polygon", "center", "size", "kind"]),
    st.lists(vertex, max_size=8) | values,
    min_size=1,
    max_size=2,
)
FIELDS = [
    ("robot", "name"),
    ("scene", "generator"),
    ("scene", "seed"),
    ("start", "q"),
    ("goal", "q"),
    ("goal", "position"),
    ("options", "waypoints"),
    ("options", "margin"),
    ("options", "max_step"),
    ("options", "lower"),
    ("solver", "rrt_step"),
    ("solver", "interpolated"),
    ("solver", "ipopt"),
    ("solver", "per_link"),
    ("seed", "count"),
    ("seed", "kinds"),
    ("seed", "time_budget"),
    ("refine", "rounds"),
    ("ipopt", "interpolated"),
    ("ipopt", "options"),
    ("adam", "lr"),
]


@st.composite
def problem_texts(draw) -> bytes:
    cfg = {k: dict(v) for k, v in BASE.items()}
    for table, key in draw(st.lists(st.sampled_from(FIELDS), max_size=4)):
        cfg.setdefault(table, {})[key] = draw(values)
    for table in draw(st.lists(st.sampled_from(sorted(cfg)), max_size=2)):
        cfg[table] = draw(values) if draw(st.booleans()) else {}
    if draw(st.booleans()):
        cfg["obstacles"] = draw(st.lists(obstacle, min_size=1, max_size=3))
    if draw(st.booleans()):
        cfg[draw(st.text(min_size=1, max_size=6))] = draw(values)
    try:
        text = tomli_w.dumps(cfg).encode()
    except (TypeError, ValueError):  # a top-level non-table: write it as a key anyway
        text = b"start = [1, 2]\n"
    if draw(st.booleans()):
        at = draw(st.integers(0, len(text)))
        text = text[:at] + draw(st.binary(max_size=6)) + text[at:]
    return text


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(text=problem_texts())
def test_any_problem_file_is_a_problem_or_one_gdnplan_error(tmp_path_factory, text):
    path = tmp_path_factory.mktemp("fuzz") / "p.toml"
    path.write_bytes(text)
    try:
        Problem.from_toml(path)
    except GdnplanError as e:
        assert str(e) and "\n" not in str(e).strip()


@settings(max_examples=6, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(text=problem_texts())
def test_the_cli_answers_any_problem_file_in_one_line(tmp_path_factory, text):
    folder = tmp_path_factory.mktemp("cli")
    path, out = folder / "p.toml", folder / "scene.png"
    path.write_bytes(text)
    proc = subprocess.run(
        [
            sys.executable,
            "-c",
            "from gdnplan.cli import main; main()",
            "show",
            str(path),
            "--out",
            str(out),
        ],
        capture_output=True,
        text=True,
        timeout=ANSWER_TIMEOUT,
    )
    assert proc.returncode in (0, 2), proc.stderr
    assert "Traceback" not in proc.stderr
    if proc.returncode == 2:
        lines = proc.stderr.strip().splitlines()  # warnings first (an old [solver] table), then
        assert all(line.startswith("warning: ") for line in lines[:-1]), proc.stderr
        assert lines[-1].startswith("error:")  # one error line
        assert not out.exists()
    assert not [p.name for p in folder.iterdir() if p.name.startswith(".")]  # no temp left
