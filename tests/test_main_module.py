"""``python -m gdnplan`` is the ``gdnplan`` command."""

import subprocess
import sys


def test_python_m_gdnplan_runs_the_cli():
    out = subprocess.run(
        [sys.executable, "-m", "gdnplan", "--help"], capture_output=True, text=True, timeout=120
    )
    assert out.returncode == 0, out.stderr
    assert "Usage: gdnplan" in out.stdout and "plan" in out.stdout
