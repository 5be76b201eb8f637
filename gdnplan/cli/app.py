"""The typer app, its ``--debug``/``--version`` callback and :func:`run`: every error as one line
and the exit status of :mod:`gdnplan.cli`."""

from __future__ import annotations

import contextlib
import errno
import os
import sys
import traceback
import warnings
from typing import TYPE_CHECKING

import typer

from ..errors import GdnplanError

if TYPE_CHECKING:  # the commands import numpy and the library when they run: a fast --help
    pass

try:  # typer ≥ 0.25 vendors click
    from typer._click import exceptions as click_exceptions
except ImportError:  # pragma: no cover - older typer depends on click
    from click import exceptions as click_exceptions

from .common import hide_progress

app = typer.Typer(
    help="Collision-free trajectory planning with GraphDistNet.",
    no_args_is_help=True,
    pretty_exceptions_enable=False,
    add_completion=False,
    rich_markup_mode=None,  # plain help: rendering it with rich costs ≈ 0.3 s per --help
    context_settings={"max_content_width": 100},  # up to 100 columns in a wide terminal
)


EXIT_FAILED, EXIT_INPUT, EXIT_INTERNAL, EXIT_INTERRUPTED = 1, 2, 3, 130


_DEBUG = {"on": False}  # set by ``--debug`` (the callback runs before the command)


def _print_version(value: bool) -> None:
    if value:
        from importlib.metadata import version

        typer.echo(f"gdnplan {version('gdnplan')}")
        raise typer.Exit()


@app.callback()
def _commands(
    debug: bool = typer.Option(False, "--debug", help="Print the traceback of any error."),
    version: bool = typer.Option(
        False, "--version", callback=_print_version, is_eager=True, help="Print the version."
    ),
) -> None:
    """Collision-free trajectory planning with GraphDistNet."""
    _DEBUG["on"] = debug


def run(args: list[str] | None = None) -> None:
    """Run the app on ``args`` (default: the command line); exits with the status of the module
    docstring, every error as one line on stderr."""
    _DEBUG["on"] = False
    shown, warnings.showwarning = warnings.showwarning, _warning_line
    try:
        code = app(args=args, prog_name="gdnplan", standalone_mode=False)
        if code == EXIT_INTERRUPTED:  # typer returns Ctrl-C in a command as exit code 130
            typer.echo("error: interrupted", err=True)
    except click_exceptions.NoArgsIsHelpError as e:
        e.show()
        code = EXIT_INPUT
    except click_exceptions.UsageError as e:
        hint = f"; see `{e.ctx.command_path} --help`" if e.ctx is not None else ""
        code = _fail(e, one_line(e.format_message()) + hint, EXIT_INPUT)
    except GdnplanError as e:
        code = _fail(e, one_line(str(e)), EXIT_INPUT)
    except (KeyboardInterrupt, typer.Abort) as e:
        code = _fail(e, "interrupted", EXIT_INTERRUPTED)
    except OSError as e:  # a full disk or a closed pipe behind stdout: no bug of gdnplan
        why = f"standard output: cannot write ({e.strerror or type(e).__name__}); redirect it"
        code = _fail(e, why, EXIT_INPUT) if _stdout_failed(e) else _internal(e)
    except Exception as e:  # the last resort: a bug, never a traceback without --debug
        code = _internal(e)
    finally:
        hide_progress()
        warnings.showwarning = shown
    sys.exit(code if isinstance(code, int) else 0)


def _internal(e: Exception) -> int:
    """Print a bug's one line ``internal error (…)``; returns :data:`EXIT_INTERNAL`."""
    why = f"{type(e).__name__}: {one_line(str(e))}" if str(e) else type(e).__name__
    return _fail(e, f"internal error ({why}); rerun with --debug for the traceback", EXIT_INTERNAL)


OUTPUT_ERRNOS = {errno.EPIPE, errno.ENOSPC, errno.EIO, errno.EDQUOT, errno.EFBIG}


def _stdout_failed(e: OSError) -> bool:
    """``e`` came from writing standard output (``> /dev/full``, a full disk, a reader that
    closed the pipe): its errno is a write failure and the innermost frame of its traceback was
    writing to a stream on file descriptor 1 (library files raise OutputError, never a bare
    OSError). Standard output is then pointed at the null device, so the interpreter's own
    flush at exit does not fail again."""
    if e.errno not in OUTPUT_ERRNOS:
        return False
    tb = e.__traceback__
    while tb is not None and tb.tb_next is not None:
        tb = tb.tb_next
    streams = tb.tb_frame.f_locals.values() if tb is not None else ()
    if not any(_on_stdout(v) for v in streams):
        return False
    with contextlib.suppress(OSError, ValueError, AttributeError):
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
    return True


def _on_stdout(value: object) -> bool:
    """``value`` is a stream writing to file descriptor 1."""
    try:
        return hasattr(value, "write") and value.fileno() == 1
    except (OSError, ValueError, AttributeError, TypeError):  # a closed or in-memory stream
        return False


def _warning_line(message, category, filename, lineno, file=None, line=None) -> None:
    """A warning the filters let through as one line ``warning: …`` on stderr."""
    typer.echo(f"warning: {one_line(str(message))}", err=True)


def _fail(e: BaseException, message: str, code: int) -> int:
    """Print ``error: message`` (after the traceback with ``--debug``); returns ``code``."""
    if _DEBUG["on"]:
        traceback.print_exception(e)
    typer.echo(f"error: {message}", err=True)
    return code


def one_line(text: str, limit: int = 400) -> str:
    """``text`` on one line (whitespace runs become one space), at most ``limit`` characters."""
    flat = " ".join(text.split())
    return flat if len(flat) <= limit else flat[: limit - 1] + "…"


def main() -> None:
    """Console entry point."""
    run()
