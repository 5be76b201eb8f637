"""Fast start: what ``import gdnplan``, ``gdnplan --help`` and a coal-only plan load; the CLI's
progress lines. Every check runs in a fresh interpreter (sys.modules of this one is shared by
all tests) and asserts on the modules loaded, never on time."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

import gdnplan as gp
from gdnplan.cli import run

ROOT = Path(__file__).resolve().parent.parent
SQUARE = ROOT / "problems" / "planar2_square.toml"
# torch is 2 s of import; the others are what the commands import when they run
HEAVY = ("torch", "casadi", "pinocchio", "coal", "matplotlib", "scipy", "shapely", "rich")


def loaded_after(code: str) -> dict:
    """Run ``code`` in a fresh interpreter; the heavy top-level modules it left loaded, and
    what ``code`` printed (stdout) and logged (stderr)."""
    script = (
        "import json, sys\n"
        f"{code}\n"
        f"print(json.dumps(sorted(m for m in {HEAVY!r} if m in sys.modules)), file=sys.stderr)"
    )
    proc = subprocess.run(
        [sys.executable, "-c", script], capture_output=True, text=True, cwd=ROOT, timeout=600
    )
    *err, last = proc.stderr.strip().splitlines()
    return {"modules": json.loads(last), "stdout": proc.stdout, "stderr": err}


def run_cli(*args: str) -> str:
    """Code that runs the CLI on ``args`` in-process and swallows its exit."""
    call = f"run({list(args)!r})"
    return f"from gdnplan.cli import run\ntry:\n    {call}\nexcept SystemExit:\n    pass"


def test_import_gdnplan_and_cli_load_no_heavy_module():
    got = loaded_after("import gdnplan, gdnplan.cli, gdnplan.errors")
    assert got["modules"] == []


HELPS = [["--help"], ["plan", "--help"], ["reproduce", "table2", "--help"]]


@pytest.mark.parametrize("args", HELPS)
def test_help_loads_no_heavy_module(args):
    got = loaded_after(run_cli(*args))
    assert "Usage: gdnplan" in got["stdout"]
    assert got["modules"] == []


def test_coal_plan_does_not_import_torch():
    got = loaded_after(run_cli("plan", str(SQUARE), "--collision", "coal", "--json"))
    assert json.loads(got["stdout"])["success"] is True
    assert "coal" in got["modules"] and "torch" not in got["modules"]


def test_registries_load_the_ur5e_module_on_demand():
    got = loaded_after(
        "from gdnplan.robot import load_robot, robot_names\n"
        "from gdnplan.scene import scene_names\n"
        "assert 'gdnplan.ur5e' not in sys.modules\n"
        "print(json.dumps([robot_names(), scene_names(), load_robot('ur5').name]))"
    )
    robots, scenes, ur5 = json.loads(got["stdout"])
    assert {"ur5e", "ur5", "planar2"} <= set(robots) and "fetch" in scenes and ur5 == "ur5"
    assert "torch" not in got["modules"]


def test_every_public_name_resolves_and_is_listed():
    for name in gp.__all__:
        assert getattr(gp, name) is not None, name
    assert set(gp.__all__) <= set(dir(gp))
    assert gp.trajopt.plan is gp.plan  # a submodule loads on attribute access
    with pytest.raises(AttributeError, match="no attribute 'not_a_name'"):
        gp.not_a_name  # noqa: B018
    namespace: dict = {}
    exec("from gdnplan import *", namespace)
    assert set(gp.__all__) <= set(namespace)


def test_every_public_name_resolves_in_a_fresh_interpreter():
    got = loaded_after(
        "import gdnplan as gp\n"
        "missing = [n for n in gp.__all__ if getattr(gp, n, None) is None]\n"
        "print(json.dumps(missing))"
    )
    assert json.loads(got["stdout"]) == []


def _plan(capsys, *flags: str) -> tuple[dict, list[str]]:
    with pytest.raises(SystemExit) as exit_:
        run(["plan", str(SQUARE), "--collision", "coal", "--json", *flags])
    out, err = capsys.readouterr()
    assert exit_.value.code == 0, err
    return json.loads(out), err.splitlines()


def test_plan_json_stdout_is_clean_and_stage_lines_go_to_stderr(capsys):
    summary, err = _plan(capsys)
    assert summary["success"] is True
    stages = [line.split(":", 1)[0] for line in err]
    assert "seed" in stages and "solve" in stages and stages[-1] == "certify", err
    assert err[-1].startswith("certify: coal certificate ok, clearance ≥ +0.0")


def test_quiet_silences_the_stage_lines(capsys):
    summary, err = _plan(capsys, "--quiet")
    assert summary["success"] is True and err == []
    summary, err = _plan(capsys, "-q")
    assert err == []


def test_progress_handler_is_detached_after_a_command(capsys):
    _plan(capsys)
    gp.plan(gp.Problem.from_toml(SQUARE), collision="coal")  # the library alone prints nothing
    assert capsys.readouterr().err == ""


def test_a_numba_environment_numba_refuses_is_one_input_error():
    """Audit: NUMBA_NUM_THREADS=0 made numba's import raise ValueError inside the first learned
    model loaded (`gdnplan plan … --collision graphdistnet`: internal error, exit 3)."""
    import os

    code = (
        "import gdnplan as gp\n"
        "try:\n"
        "    gp.load_model('d')\n"
        "except gp.InputError as e:\n"
        "    print('refused:', e)\n"
    )
    env = {**os.environ, "NUMBA_NUM_THREADS": "0"}
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    assert out.stdout.startswith("refused: NUMBA_NUM_THREADS") and "positive integer" in out.stdout
