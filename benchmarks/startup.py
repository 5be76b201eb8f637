"""Start-up time of the command line and the library: median wall time of fresh interpreters.

Usage: python benchmarks/startup.py [--runs 5] [--root DIR …]

Each command runs ``--runs`` times as a subprocess (``python -m gdnplan.cli --help``,
``python -m gdnplan.cli plan --help``, ``python -c "import gdnplan"``, and ``python -c pass``
for the interpreter alone), with ``PYTHONPATH`` set to each ``--root`` (a gdnplan checkout;
default: this one), so two checkouts are measured side by side: e.g. ``--root /path/to/old
--root .``. Prints a markdown table of the medians (s) with the machine, date and load average
(other jobs may share the CPU: compare the columns of one run, not runs).
"""

from __future__ import annotations

import argparse
import datetime
import os
import platform
import statistics
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
COMMANDS = {
    "gdnplan --help": ["-m", "gdnplan.cli", "--help"],
    "gdnplan plan --help": ["-m", "gdnplan.cli", "plan", "--help"],
    "import gdnplan": ["-c", "import gdnplan"],
    "python (no import)": ["-c", "pass"],
}


def median_seconds(args: list[str], root: Path, runs: int) -> float:
    """Median wall time (s) of ``runs`` runs of ``python args`` with gdnplan from ``root``."""
    env = {**os.environ, "PYTHONPATH": str(root)}
    times = []
    for _ in range(runs):
        start = time.perf_counter()
        subprocess.run([sys.executable, *args], env=env, cwd=root, capture_output=True, check=True)
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--runs", type=int, default=5)
    parser.add_argument("--root", type=Path, action="append", help="gdnplan checkout(s)")
    args = parser.parse_args()
    roots = [r.resolve() for r in args.root or [ROOT]]
    now = datetime.datetime.now(datetime.UTC).strftime("%Y-%m-%d %H:%M UTC")
    cpu = platform.processor() or platform.machine()
    python = platform.python_version()
    print(f"machine: {platform.node()}, {cpu}, {os.cpu_count()} cores, Python {python}; {now}")
    print(f"load average at start: {os.getloadavg()}; median of {args.runs} runs (s)")
    print("| command | " + " | ".join(str(r) for r in roots) + " |")
    print("|---" * (len(roots) + 1) + "|")
    for name, command in COMMANDS.items():
        cells = [f"{median_seconds(command, root, args.runs):.2f}" for root in roots]
        print(f"| `{name}` | " + " | ".join(cells) + " |", flush=True)
    print(f"load average at end: {os.getloadavg()}")


if __name__ == "__main__":
    main()
