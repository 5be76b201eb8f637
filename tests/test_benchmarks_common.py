"""benchmarks/common.py: one way to run every benchmark script, one header, timer and writer."""

import ast
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "benchmarks"))
import common  # noqa: E402

SCRIPTS = sorted(
    p for p in (ROOT / "benchmarks").glob("*.py") if p.name != "common.py" and "ompl" not in p.name
)


@pytest.mark.parametrize("script", SCRIPTS, ids=lambda p: p.name)
def test_every_script_runs_through_common(script):
    """Each script builds its parser with common.parser, parses with common.parse and writes a
    common.Report (so it takes --threads and --out and records the shared header)."""
    calls = {
        f"{n.func.value.id}.{n.func.attr}"
        for n in ast.walk(ast.parse(script.read_text()))
        if isinstance(n, ast.Call)
        and isinstance(n.func, ast.Attribute)
        and isinstance(n.func.value, ast.Name)
    }
    assert {"common.parser", "common.parse", "common.Report"} <= calls, script.name
    assert f'common.parser("{script.stem}"' in script.read_text()


def test_parse_applies_threads_and_defaults_out(monkeypatch):
    import torch

    from gdnplan.models import inference_threads, set_inference_threads

    before = torch.get_num_threads()
    try:
        args = common.parse(common.parser("demo", "doc"), ["--threads", "1"])
        assert args.out == ROOT / "benchmarks" / "results" / "demo.md"
        assert inference_threads() == 1 and torch.get_num_threads() == 1
    finally:
        torch.set_num_threads(before)
        set_inference_threads(1)
    with pytest.raises(SystemExit):
        common.parse(common.parser("demo", "doc"), ["--threads", "0"])


def test_time_calls_interleaves_after_warmup():
    order = []
    calls = {"a": lambda: order.append("a"), "b": lambda: order.append("b")}
    t = common.time_calls(calls, repeats=3, warmup=1)
    assert order == ["a", "b"] * 4
    assert len(t["a"].times) == 3 and t["a"].best <= t["a"].median


def test_report_writes_header_and_tables(tmp_path, monkeypatch):
    monkeypatch.setattr(sys, "argv", [str(ROOT / "benchmarks" / "demo.py"), "--threads", "1"])
    args = common.parser("demo", "doc").parse_args(["--out", str(tmp_path / "r.md")])
    report = common.Report(args, "Demo", "what it measures")
    report.text("intro")
    table = report.table("x", "y")
    table.add(1, "2.0")
    text = report.write().read_text()
    for part in (
        "# Demo",
        "command: `python benchmarks/demo.py --threads 1`",
        "- date: ",
        "- machine: ",
        "torch ",
        "coal ",
        "casadi ",
        "numpy ",
        "- git: ",
        "intro",
        "| x | y |\n|---|---|\n| 1 | 2.0 |",
    ):
        assert part in text, part
