"""The exit-code contract every ``graspaug`` command keeps, the command class that keeps it (one error handler
for the whole CLI), and the options the commands share."""

from __future__ import annotations

import errno
import logging
import re
import warnings
from pathlib import Path

import typer
from typer.core import TyperCommand

EXIT_CODES = (
    "Exit codes, the same for every command: 0 an answer; 1 no acceptable answer (`plan`: no grasp, or the best one "
    "below the quality floor); 2 bad input or usage (a missing or broken file, a bad param, an output folder it may "
    "not write, too few usable candidates for `--count`), one line naming the culprit; 3 an unexpected error (a bug: "
    "`graspaug --debug <command> ...` shows its traceback), or the system failing the command (disk full, permission "
    "denied, an I/O error: its cause named)."
)

ParamsOption = typer.Option(Path("params.yaml"), "--params", "-p", help="The params file to read.")
ForceOption = typer.Option(
    False,
    "--force",
    help="Write into an output folder that holds files this command did not write: those of the names it writes are "
    "replaced, the others kept.",
)


_debug = {"on": False}  # set by the root callback (--debug, GRASPAUG_DEBUG) on every invocation


def debug_mode(on: bool) -> None:
    """Show tracebacks and every warning each time it is raised (``--debug``) or not, for the commands invoked
    next."""
    _debug["on"] = bool(on)


def _bad_input_errors() -> tuple[type[BaseException], ...]:
    """The errors that mean bad input or usage (exit 2): each carries a one-line message naming the culprit."""
    from graspaug.errors import CheckpointMismatch, DataError, StageError  # the planner's PlanningError is a DataError
    from graspaug.pipeline.params.base import ParamsError

    return (DataError, StageError, CheckpointMismatch, ParamsError, OSError)


#: errno values of an OSError that mean the user's input or usage (a path that is missing, a folder where a file
#: belongs, an output that exists): exit 2. Any other errno (ENOSPC, EACCES, EIO, EROFS, ...) is the system
#: failing the command: exit 3 with the cause. An OSError without errno (a library's message) is bad input.
INPUT_ERRNOS = frozenset(
    {errno.ENOENT, errno.EISDIR, errno.ENOTDIR, errno.EEXIST, errno.ENOTEMPTY, errno.ENAMETOOLONG, errno.ELOOP}
)

#: Warnings Python itself hides by default (meant for developers of the raising package), hidden here too.
_QUIET = (DeprecationWarning, PendingDeprecationWarning, ImportWarning, ResourceWarning)


class WarningsOnce:
    """A ``warnings.showwarning`` that logs each distinct warning (category and text) once, on the
    ``py.warnings`` logger at WARNING level, with the file and line that raised it: a third-party warning
    (torch, sklearn, trimesh) reaches the stage's log without repeating for every shape."""

    def __init__(self) -> None:
        self.seen: set[tuple[type, str]] = set()

    def __call__(self, message, category, filename, lineno, file=None, line=None) -> None:
        key = (category, str(message))
        if key in self.seen:
            return
        self.seen.add(key)
        where = "/".join(str(filename).split("/")[-2:])
        text = " ".join(str(message).split())
        logging.getLogger("py.warnings").warning("%s: %s (%s:%s)", category.__name__, text, where, lineno)


def is_system_error(exc: BaseException) -> bool:
    """Whether ``exc`` is the system failing the command (an OSError whose errno is not in :data:`INPUT_ERRNOS`:
    disk full, permission denied, I/O error...) rather than bad input."""
    return isinstance(exc, OSError) and exc.errno is not None and exc.errno not in INPUT_ERRNOS


def keep_placeholders(text: str | None) -> str | None:
    """``text`` (a help text, rendered as markdown) with every ``<`` outside a code span escaped, so a placeholder
    such as ``d<k>-s0/`` or ``results/<name>/`` is printed, not taken for an HTML tag and dropped. Idempotent."""
    if not text:
        return text
    parts = text.split("`")
    parts[::2] = [re.sub(r"(?<!\\)<", r"\\<", part) for part in parts[::2]]  # even parts: outside backticks
    return "`".join(parts)


class Command(TyperCommand):
    """A command that keeps the exit-code contract (:data:`EXIT_CODES`): an error of bad input is one line and exit
    2, the system failing (:func:`is_system_error`) or any other exception one line and exit 3; ``--debug``
    re-raises them (the traceback). Warnings are logged, each distinct one once (:class:`WarningsOnce`);
    ``--debug`` leaves Python's warning filters as they are."""

    def format_help(self, ctx, formatter) -> None:
        self.help = keep_placeholders(self.help)
        for param in self.params:
            if getattr(param, "help", None):
                param.help = keep_placeholders(param.help)
        super().format_help(ctx, formatter)

    def invoke(self, ctx):
        if _debug["on"]:
            return super().invoke(ctx)
        with warnings.catch_warnings():
            warnings.simplefilter("always")  # every call reaches WarningsOnce, which keeps the first of each
            for category in _QUIET:
                warnings.filterwarnings("ignore", category=category)
            warnings.showwarning = WarningsOnce()
            try:
                return super().invoke(ctx)
            except (typer.Exit, typer.Abort, KeyboardInterrupt):
                raise
            except _bad_input_errors() as exc:
                if is_system_error(exc):
                    typer.echo(
                        f"error: {_one_line(exc)} ({errno.errorcode.get(exc.errno, exc.errno)}: the system failed "
                        "the command, not its input; fix that and run it again)",
                        err=True,
                    )
                    raise typer.Exit(code=3) from None
                typer.echo(f"error: {_one_line(exc)}", err=True)
                raise typer.Exit(code=2) from None
            except Exception as exc:  # noqa: BLE001 - the contract: one line, exit 3, the traceback with --debug
                if type(exc).__name__ in ("BadParameter", "UsageError"):  # raised by a command's body (typer's click)
                    typer.echo(f"error: {_one_line_usage(exc)}", err=True)
                    raise typer.Exit(code=2) from None
                if type(exc).__module__.startswith(("click", "typer._click")):
                    raise
                typer.echo(
                    f"error: unexpected {type(exc).__name__}: {_one_line(exc)} (a bug? `graspaug --debug` shows "
                    "the traceback)",
                    err=True,
                )
                raise typer.Exit(code=3) from None


def _one_line_usage(exc: BaseException) -> str:
    """A usage error raised by a command's body as one line: ``--option: message`` (click's own words otherwise)."""
    hint = getattr(exc, "param_hint", None)
    if isinstance(hint, str) and hasattr(exc, "message"):
        return " ".join(f"{hint}: {exc.message}".split())
    return " ".join((exc.format_message() if hasattr(exc, "format_message") else str(exc)).split())


def _one_line(exc: BaseException) -> str:
    text = " ".join(str(exc).split()) if str(exc) else type(exc).__name__
    if isinstance(exc, OSError) and exc.filename is not None and exc.strerror:
        text = f"{exc.filename}: {exc.strerror.lower()}"
    return text
