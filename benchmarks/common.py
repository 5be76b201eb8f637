"""What every benchmark script shares: one way to run it, one header, one timer, one writer.

Every script is run the same way, from the repository root::

    python benchmarks/X.py --threads 1 [its own options]

- :func:`parser` gives the two common options: ``--threads`` (the torch threads of the learned
  models' inference and of torch itself, as the CLI's ``--threads``: gdnplan's
  :func:`~gdnplan.models.set_inference_threads` and ``torch.set_num_threads``) and ``--out``
  (default ``benchmarks/results/<script>.md``); :func:`parse` parses, applies the threads and
  checks that ``--out`` can be written before the (long) run.
- :class:`Report` takes the header when the run starts (command line, date UTC, machine: CPU
  model, cores, load average, Python, torch / coal / casadi / numpy versions, git commit),
  collects the script's text and :class:`Table` s (printing each row as it is measured) and
  writes them, with the load average and time at the end, to ``--out``.
- :func:`time_calls` times several calls side by side: one warm-up call each, then ``repeats``
  rounds in which every call runs once, so a change of load hits all of them alike; it returns
  the best and the median of each. The machine is shared: compare the ratios of one run.
"""

from __future__ import annotations

import argparse
import datetime
import importlib.metadata
import os
import platform
import shlex
import statistics
import subprocess
import sys
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
RESULTS = ROOT / "benchmarks" / "results"
PACKAGES = ("torch", "coal", "casadi", "numpy")


def parser(script: str, doc: str | None) -> argparse.ArgumentParser:
    """An argument parser for ``benchmarks/<script>.py`` with ``--threads`` and ``--out``;
    ``doc`` (the script's docstring) is its description."""
    p = argparse.ArgumentParser(
        prog=f"python benchmarks/{script}.py",
        description=doc,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument(
        "--threads",
        type=int,
        default=1,
        help="torch threads of the learned models' inference and of torch (default 1)",
    )
    p.add_argument(
        "--out",
        type=Path,
        default=RESULTS / f"{script}.md",
        help=f"results file (default benchmarks/results/{script}.md)",
    )
    return p


def apply_threads(threads: int) -> None:
    """gdnplan's thread setting, as the CLI's ``--threads``: the learned models' inference
    threads and torch's own intra-op threads (InputError unless ≥ 1)."""
    from gdnplan.models import set_inference_threads

    set_inference_threads(threads)
    import torch

    torch.set_num_threads(threads)


def parse(p: argparse.ArgumentParser, argv: Sequence[str] | None = None) -> argparse.Namespace:
    """Parse the command line, apply ``--threads`` and check ``--out`` before the run."""
    from gdnplan.files import check_output_path

    args = p.parse_args(argv)
    if args.threads < 1:
        p.error(f"--threads: expected an integer ≥ 1, got {args.threads}")
    check_output_path(args.out, (".md",), "--out")
    apply_threads(args.threads)
    return args


def cpu_model() -> str:
    """The CPU's model name (``lscpu``, else /proc/cpuinfo, else ``platform``)."""
    try:
        out = subprocess.run(["lscpu"], capture_output=True, text=True, check=False).stdout
    except OSError:
        out = ""
    try:
        out += Path("/proc/cpuinfo").read_text()
    except OSError:
        pass
    for line in out.splitlines():
        key, _, value = line.partition(":")
        if key.strip().lower() in ("model name", "model_name"):
            return value.strip()
    return platform.processor() or platform.machine()


def versions() -> str:
    """``torch 2.x, coal 3.x, …`` of :data:`PACKAGES` (``–`` where not installed)."""
    out = []
    for name in PACKAGES:
        try:
            out.append(f"{name} {importlib.metadata.version(name)}")
        except importlib.metadata.PackageNotFoundError:
            out.append(f"{name} –")
    return ", ".join(out)


def git_commit() -> str:
    """Short commit of the checkout, with ``+ uncommitted changes`` when tracked files differ."""

    def git(*args: str) -> str:
        run = subprocess.run(["git", *args], cwd=ROOT, capture_output=True, text=True, check=False)
        return run.stdout.strip()

    sha = git("rev-parse", "--short", "HEAD") or "unknown"
    dirty = git("status", "--porcelain", "--untracked-files=no")
    return f"{sha} + uncommitted changes" if dirty else sha


def command_line(argv: Sequence[str] | None = None) -> str:
    """The command as run from the repository root: ``python benchmarks/X.py …``."""
    argv = list(sys.argv if argv is None else argv)
    script = Path(argv[0]).resolve()
    if script.is_relative_to(ROOT):
        argv[0] = str(script.relative_to(ROOT))
    return shlex.join(["python", *argv])


def utc_now() -> str:
    return f"{datetime.datetime.now(datetime.UTC):%Y-%m-%d %H:%M} UTC"


def kernel_blas() -> str:
    """The BLAS the fused kernels' products call (gdnplan.models.graphdistnet.gemm.BACKEND)."""
    from gdnplan.models.graphdistnet import gemm

    return gemm.BACKEND


def header(threads: int) -> str:
    """The run's header as a markdown list (taken when the run starts)."""
    load = ", ".join(f"{x:.2f}" for x in os.getloadavg())
    return "\n".join(
        [
            f"- command: `{command_line()}`",
            f"- date: {utc_now()}",
            f"- machine: {cpu_model()}, {os.cpu_count()} cores, {platform.system()}; "
            f"load average at the start {load} (a shared machine: compare ratios, not seconds)",
            f"- Python {platform.python_version()}, {versions()}",
            f"- git: {git_commit()}",
            f"- threads: {threads} (inference and torch)",
            f"- products of the compiled kernels: {kernel_blas()}",
        ]
    )


@dataclass
class Table:
    """A markdown table whose rows are printed as they are added."""

    head: Sequence[str]
    rows: list[list[str]] = field(default_factory=list)

    @staticmethod
    def _line(cells: Sequence[object]) -> str:
        return "| " + " | ".join(str(c) for c in cells) + " |"

    def add(self, *cells: object) -> None:
        """Append one row (and print it; the head too before the first row)."""
        if not self.rows:
            print(self._line(self.head), "|---" * len(self.head) + "|", sep="\n")
        self.rows.append([str(c) for c in cells])
        print(self._line(cells), flush=True)

    def __str__(self) -> str:
        lines = [self._line(self.head), "|---" * len(self.head) + "|"]
        return "\n".join(lines + [self._line(r) for r in self.rows])


class Report:
    """A results file: title, what the script measures, the header, then text and tables."""

    def __init__(self, args: argparse.Namespace, title: str, about: str = "") -> None:
        self.out: Path = args.out
        self.title = title
        self.about = about.strip()
        self.header = header(args.threads)
        self.parts: list[str | Table] = []
        print(f"# {title}\n\n{self.header}\n", flush=True)

    def text(self, text: str) -> None:
        """Append a paragraph (and print it)."""
        self.parts.append(text.strip())
        print(text.strip(), flush=True)

    def table(self, *head: str) -> Table:
        """Append a new :class:`Table` with these column heads and return it."""
        table = Table(head)
        self.parts.append(table)
        return table

    def write(self) -> Path:
        """Write the file (atomically); returns its path."""
        from gdnplan.files import write_text

        load = ", ".join(f"{x:.2f}" for x in os.getloadavg())
        body = "\n\n".join(str(p) for p in self.parts if str(p))
        about = f"{self.about}\n\n" if self.about else ""
        text = (
            f"# {self.title}\n\n{about}{self.header}\n- finished: {utc_now()}, "
            f"load average {load}\n\n{body}\n"
        )
        write_text(self.out, text, "--out")
        print(f"\nwrote {self.out}", flush=True)
        return self.out


@dataclass(frozen=True)
class Timing:
    """Wall times (s) of the timed calls of one function (warm-up excluded)."""

    times: tuple[float, ...]

    @property
    def best(self) -> float:
        return min(self.times)

    @property
    def median(self) -> float:
        return statistics.median(self.times)


def time_calls(
    calls: dict[str, Callable[[], object]], repeats: int = 3, warmup: int = 1
) -> dict[str, Timing]:
    """Time every call side by side: ``warmup`` untimed rounds, then ``repeats`` rounds in
    which each call runs once (interleaved, so a change of load hits them alike)."""
    for _ in range(warmup):
        for fn in calls.values():
            fn()
    times: dict[str, list[float]] = {name: [] for name in calls}
    for _ in range(repeats):
        for name, fn in calls.items():
            start = time.perf_counter()
            fn()
            times[name].append(time.perf_counter() - start)
    return {name: Timing(tuple(t)) for name, t in times.items()}


def first_paragraph(doc: str | None) -> str:
    """The first paragraph of a docstring (what a script measures)."""
    return (doc or "").strip().split("\n\n")[0].replace("\n", " ")
