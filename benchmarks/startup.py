"""Start-up time of the command line and the library: median wall time of fresh interpreters.

Each command runs ``--runs`` times as a subprocess (``python -m gdnplan.cli --help``,
``python -m gdnplan.cli plan --help``, ``python -c "import gdnplan"``, and ``python -c pass``
for the interpreter alone), with ``PYTHONPATH`` set to each ``--root`` (a gdnplan checkout;
default: this one), so two checkouts are measured side by side, run after run (after one
warm-up run each): e.g. ``--root /path/to/old --root .``. Reports the medians (s).
(``--threads`` is accepted for the common command line; the measured interpreters start with
gdnplan's defaults.)

    python benchmarks/startup.py --threads 1 [--runs 5] [--root DIR …]
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import common

COMMANDS = {
    "gdnplan --help": ["-m", "gdnplan.cli", "--help"],
    "gdnplan plan --help": ["-m", "gdnplan.cli", "plan", "--help"],
    "import gdnplan": ["-c", "import gdnplan"],
    "python (no import)": ["-c", "pass"],
}


def launcher(args: list[str], root: Path):
    """A call running ``python args`` with gdnplan from ``root``."""
    env = {**os.environ, "PYTHONPATH": str(root)}
    return lambda: subprocess.run(
        [sys.executable, *args], env=env, cwd=root, capture_output=True, check=True
    )


def main() -> None:
    p = common.parser("startup", __doc__)
    p.add_argument("--runs", type=int, default=5)
    p.add_argument("--root", type=Path, action="append", help="gdnplan checkout(s)")
    args = common.parse(p)
    roots = [r.resolve() for r in args.root or [common.ROOT]]
    report = common.Report(args, "Start-up time", common.first_paragraph(__doc__))
    report.text(f"Median of {args.runs} fresh interpreters per command and checkout (s).")
    table = report.table("command", *(str(r) for r in roots))
    for name, command in COMMANDS.items():
        calls = {str(root): launcher(command, root) for root in roots}
        t = common.time_calls(calls, repeats=args.runs)
        table.add(f"`{name}`", *(f"{t[str(r)].median:.2f}" for r in roots))
    report.write()


if __name__ == "__main__":
    main()
