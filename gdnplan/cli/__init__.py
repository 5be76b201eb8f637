"""The ``gdnplan`` command.

Exit status: 0 success; 1 planning failed (``plan``, ``fetch``); 2 bad input (a
:class:`~gdnplan.errors.GdnplanError`, a usage error or a standard output that cannot be written,
e.g. ``> /dev/full``: one line ``error: …`` naming the field and the fix); 3 internal error (any
other exception: one line ``error: internal error (Type: message); rerun with --debug for the
traceback``); 130 interrupted (Ctrl-C). ``gdnplan --debug <command> …`` prints the traceback of
errors 2 and 3 as well.

The command lives in a package by concern: :mod:`~gdnplan.cli.app` (the app and :func:`run`),
:mod:`~gdnplan.cli.common` (what the commands share), :mod:`~gdnplan.cli.plan` (``show``, ``plan``;
their reports: :mod:`~gdnplan.cli.plan_report`), :mod:`~gdnplan.cli.reproduce` (``evaluate``,
``reproduce``, ``field``), :mod:`~gdnplan.cli.reproduce_ablation` (``reproduce ablation``,
``reproduce faithful``), :mod:`~gdnplan.cli.fetch` and :mod:`~gdnplan.cli.train` (``generate``,
``train``). Importing the package registers every command.
"""

from __future__ import annotations

from . import (  # noqa: F401  (each registers its commands)
    fetch,
    plan,
    reproduce,
    reproduce_ablation,
    train,
)
from .app import EXIT_FAILED, EXIT_INPUT, EXIT_INTERNAL, EXIT_INTERRUPTED, app, main, one_line, run
from .common import (
    check_limits,
    hide_progress,
    parse_vector,
    problem_scene_and_start,
    scene_and_start,
    set_threads,
    show_progress,
)
from .plan import clearance_text, json_number, plan_summary

__all__ = [
    "EXIT_FAILED",
    "EXIT_INPUT",
    "EXIT_INTERNAL",
    "EXIT_INTERRUPTED",
    "app",
    "check_limits",
    "clearance_text",
    "hide_progress",
    "json_number",
    "main",
    "one_line",
    "parse_vector",
    "plan_summary",
    "problem_scene_and_start",
    "run",
    "scene_and_start",
    "set_threads",
    "show_progress",
]
