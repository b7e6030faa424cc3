"""The exit-code contract every ``graspaug`` command keeps, and the command class that keeps it (one error handler
for the whole CLI)."""

from __future__ import annotations

import warnings

import typer
from typer.core import TyperCommand

EXIT_CODES = (
    "Exit codes, the same for every command: 0 an answer; 1 no acceptable answer (`plan`: no grasp, or the best one "
    "below the quality floor); 2 bad input or usage (a missing or broken file, a bad param, an output folder it may "
    "not write, too few usable candidates for `--count`), one line naming the culprit; 3 an unexpected error (a bug: "
    "`graspaug --debug <command> ...` shows its traceback)."
)

_debug = {"on": False}  # set by the root callback (--debug, GRASPAUG_DEBUG) on every invocation


def debug_mode(on: bool) -> None:
    """Show tracebacks and other packages' warnings (``--debug``) or not, for the commands invoked next."""
    _debug["on"] = bool(on)


def _bad_input_errors() -> tuple[type[BaseException], ...]:
    """The errors that mean bad input or usage (exit 2): each carries a one-line message naming the culprit."""
    from graspaug.errors import CheckpointMismatch, DataError, StageError  # the planner's PlanningError is a DataError
    from graspaug.pipeline.params.base import ParamsError

    return (DataError, StageError, CheckpointMismatch, ParamsError, OSError)


class Command(TyperCommand):
    """A command that keeps the exit-code contract (:data:`EXIT_CODES`): an error of bad input is one line and exit
    2, any other exception one line and exit 3; ``--debug`` re-raises both (the traceback) and shows the warnings
    that other packages raise, which are otherwise hidden."""

    def invoke(self, ctx):
        if _debug["on"]:
            return super().invoke(ctx)
        with warnings.catch_warnings():
            warnings.filterwarnings("ignore", module=r"^(?!graspaug)")
            try:
                return super().invoke(ctx)
            except (typer.Exit, typer.Abort, KeyboardInterrupt):
                raise
            except _bad_input_errors() as exc:
                typer.echo(f"error: {_one_line(exc)}", err=True)
                raise typer.Exit(code=2) from None
            except Exception as exc:  # noqa: BLE001 - the contract: one line, exit 3, the traceback with --debug
                if type(exc).__module__.startswith("click"):
                    raise
                typer.echo(
                    f"error: unexpected {type(exc).__name__}: {_one_line(exc)} (a bug? `graspaug --debug` shows "
                    "the traceback)",
                    err=True,
                )
                raise typer.Exit(code=3) from None


def _one_line(exc: BaseException) -> str:
    text = " ".join(str(exc).split()) if str(exc) else type(exc).__name__
    if isinstance(exc, OSError) and exc.filename is not None and exc.strerror:
        text = f"{exc.filename}: {exc.strerror.lower()}"
    return text
