"""``gdnplan plan`` on 3-D problem files, through a subprocess: one error, one success."""

import json
import subprocess
import sys
from pathlib import Path

import pytest

FREE = """
[robot]
name = "ur5e"

[scene3d]
[[scene3d.obstacles]]
type = "{kind}"
{shape}
position = [0.0, 0.8, 0.3]

[start]
q = [-0.6, -1.2, 1.2, -1.5, -1.57, 0.0]

[goal]
q = [0.6, -1.2, 1.2, -1.5, -1.57, 0.0]
"""


def gdnplan(*args: str, cwd: Path) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-c", "from gdnplan.cli import main; main()", *args],
        capture_output=True,
        text=True,
        cwd=cwd,
        timeout=300,
    )


def test_a_missing_mesh_is_one_error_line_and_exit_2(tmp_path):
    problem = tmp_path / "mesh.toml"
    problem.write_text(FREE.format(kind="mesh", shape='file = "missing.stl"'))
    proc = gdnplan("plan", str(problem), "--json", cwd=tmp_path)
    assert proc.returncode == 2
    assert proc.stdout == ""
    lines = [line for line in proc.stderr.splitlines() if line.startswith("error:")]
    assert len(lines) == 1 and "missing.stl does not exist" in lines[0]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["mesh.toml"]  # nothing written


def test_a_3d_problem_plans_from_the_cli(tmp_path):
    problem = tmp_path / "free.toml"
    problem.write_text(FREE.format(kind="box", shape="size = [0.1, 0.1, 0.1]"))
    proc = gdnplan("plan", str(problem), "--json", "-q", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    summary = json.loads(proc.stdout)
    assert summary["success"] is True
    assert summary["min_distance"] > summary["clearance"] == 0.02
    assert len(summary["joint_names"]) == 6 and len(summary["q"][0]) == 6


@pytest.mark.slow  # ~10 s: RRT-Connect seed and Ipopt on the shipped UR5e problem
def test_the_shipped_ur5e_problem_plans_from_the_cli(tmp_path):
    proc = gdnplan("plan", "ur5e_boxes3d", "-q", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert "ur5e_boxes3d: certified collision-free; certified clearance ≥ +0.02" in proc.stdout
    assert "solve time" in proc.stdout
