"""The ``facemime`` command line. Errors a user can cause print one line,
``facemime: error: <message>``, on stderr and exit with status 1; ``--traceback`` shows the
Python trace instead. Data goes to stdout, progress to stderr. Exit statuses:
:class:`~facemime.cli.app.ExitStatus`."""

from __future__ import annotations

import os
import signal
import sys
import threading

import click

from facemime.cli import batch, coding, fitting, live, synthesis  # noqa: F401 (they add their commands)
from facemime.cli.app import ExitStatus, cli
from facemime.errors import FacemimeError


class Terminated(BaseException):
    """SIGTERM or SIGHUP: the command stops as on Ctrl-C, removing its unfinished outputs (a
    BaseException, like KeyboardInterrupt, but not one: click would take it for Ctrl-C)."""

    def __init__(self, signum: int):
        super().__init__(signum)
        self.signum = signum


#: Set once the command's stop has been told on stderr.
_told = threading.Event()
#: The signals that stop a command.
STOPS = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)


def _stop(signum: int, frame: object) -> None:
    """The first stop signal: the command stops as on Ctrl-C (SIGINT) or with :class:`Terminated`,
    removing its unfinished outputs as the exception unwinds; a second one while it does exits at
    once (:func:`_exit_now`)."""
    for sig in STOPS:
        signal.signal(sig, _exit_now)
    if signum == signal.SIGINT:
        raise KeyboardInterrupt
    raise Terminated(signum)


def _exit_now(signum: int, frame: object) -> None:
    """A stop signal while the command is already stopping: one line and out, with the first's
    status (128 + the signal's number; 130 for Ctrl-C). Temporary output files may be left."""
    if not _told.is_set():
        os.write(2, b"facemime: interrupted\n" if signum == signal.SIGINT else b"facemime: terminated\n")
    os._exit(128 + signum)


def main(argv: list[str] | None = None) -> None:
    """Entry point: run the CLI, turning expected errors into one line on stderr; SIGTERM and
    SIGHUP stop it cleanly (exit status 128 + the signal's number), and so does SIGINT (Ctrl-C,
    status 130) even where the process was started with SIGINT ignored, as a shell script's
    background job is: a command that says "Ctrl-C stops" stops on it. A second stop signal while
    it stops (Ctrl-C pressed again) exits at once."""
    entry, argv = argv is None, sys.argv[1:] if argv is None else argv
    _told.clear()
    handlers = {}
    if threading.current_thread() is threading.main_thread():
        handlers = {sig: signal.signal(sig, _stop) for sig in STOPS}
    try:
        _run(argv)
    finally:
        stopping = any(signal.getsignal(sig) is _exit_now for sig in handlers)
        if not (entry and stopping):  # the process exits next: a signal during its exit exits at once too
            for sig, handler in handlers.items():
                signal.signal(sig, handler)


def _run(argv: list[str]) -> None:
    ctx: click.Context | None = None
    try:
        ctx = cli.make_context("facemime", list(argv))
        with ctx:
            cli.invoke(ctx)
    except click.exceptions.Exit as e:  # --help, --version
        if e.exit_code:
            sys.exit(e.exit_code)
    except click.exceptions.Abort:
        click.echo("facemime: interrupted", err=True)
        _told.set()
        sys.exit(ExitStatus.INTERRUPTED)
    except click.ClickException as e:
        e.show()
        sys.exit(e.exit_code)
    except FacemimeError as e:
        if _traceback(ctx):
            raise
        click.echo(f"facemime: error: {e}", err=True)
        sys.exit(ExitStatus.ERROR)
    except Terminated as e:
        click.echo("facemime: terminated", err=True)
        _told.set()
        sys.exit(128 + e.signum)
    except KeyboardInterrupt:
        click.echo("facemime: interrupted", err=True)
        _told.set()
        sys.exit(ExitStatus.INTERRUPTED)
    except MemoryError:
        click.echo("facemime: error: out of memory", err=True)
        sys.exit(ExitStatus.ERROR)
    except Exception as e:  # a defect: still one line, with the way to the trace
        if _traceback(ctx):
            raise
        click.echo(
            f"facemime: error: unexpected {type(e).__name__}: {e} (a bug in facemime; run again with "
            "--traceback and report it)",
            err=True,
        )
        sys.exit(ExitStatus.BUG)


def _traceback(ctx: click.Context | None) -> bool:
    """Whether the command line asked for tracebacks (``--traceback``, before the command)."""
    return ctx is not None and bool(ctx.params.get("traceback"))
