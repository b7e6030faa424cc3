"""What every stage's own entry point shares: read the params the stage reads, log to stderr, run it under the
exit-code contract (:mod:`graspaug.pipeline.command`).

Each stage module ends with::

    if __name__ == "__main__":
        from graspaug.pipeline.entry import stage_main

        stage_main(__spec__.name)  # and its options, e.g. corpus=(str, typer.Option("original", "--corpus"))

so ``python -m graspaug.pipeline.stages.<stage> [--params FILE] [--debug] [options]`` runs it, and that is the
``cmd`` of its dvc.yaml stage: the stage's code (its ``deps``) is the import closure of its own module and of this
one, not the CLI that lists every command, so editing a help text or another stage re-runs nothing.
``graspaug <stage>`` (:mod:`graspaug.pipeline.cli`) calls the same :func:`load_params` and :func:`run_stage`.
"""

from __future__ import annotations

import importlib
import inspect
import logging
import os
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

import typer

from graspaug.pipeline.command import Command, debug_mode


def load_params(path: Path | None, model):
    """The params ``model`` (a stage's ``Params``) reads from the file at ``path`` (a bad one: ParamsError, exit 2;
    None: the built-in defaults); logging goes to stderr from here on."""
    from graspaug.pipeline.params.base import load

    logging.basicConfig(level=logging.INFO, format="%(asctime)s %(levelname)s %(name)s: %(message)s", stream=sys.stderr)
    return model() if path is None else load(path, model)


def run_stage(run: Callable[..., None], params, *args: Any) -> None:
    """``run(params, *args)``, with freed memory kept for reuse (GQ-CNN training: bench/gqcnn_train_speed.py)."""
    from graspaug.device import keep_freed_memory

    keep_freed_memory()
    run(params, *args)


def round_number(text: str) -> int:
    """A lifelong round ``r<k>`` (or ``k``) as k >= 1; anything else is a usage error naming ``--round``."""
    number = text.removeprefix("r")
    if not number.isdigit() or int(number) < 1:
        raise typer.BadParameter(f"a round r<k> with k >= 1; got {text!r}", param_hint="--round")
    return int(number)


def _debug(value: bool) -> bool:
    debug_mode(value or os.environ.get("GRASPAUG_DEBUG", "") not in ("", "0"))
    return value


def stage_main(module: str, **options: tuple[type, Any]) -> None:
    """Run stage ``module`` (``graspaug.pipeline.stages.<stage>``) from the command line: ``--params`` (default
    params.yaml), ``--debug`` (tracebacks; also GRASPAUG_DEBUG=1) and ``options``, each name → (type,
    ``typer.Option(...)``), passed to the stage's ``run(params, *values)`` in their order. Exits as every
    ``graspaug`` command does (0; 2 bad input, one line; 3 a bug)."""
    stage = importlib.import_module(module)  # by name, not as __main__: worker processes unpickle its functions

    def command(params: Path, debug: bool, **values: Any) -> None:
        run_stage(stage.run, load_params(params, stage.Params), *(values[name] for name in options))

    shared = {
        "params": (Path, typer.Option(Path("params.yaml"), "--params", "-p", help="The params file to read.")),
        "debug": (bool, typer.Option(False, "--debug", callback=_debug, is_eager=True, help="Show tracebacks.")),
    }
    kind = inspect.Parameter.KEYWORD_ONLY
    command.__signature__ = inspect.Signature(
        [
            inspect.Parameter(name, kind, default=info, annotation=cls)
            for name, (cls, info) in {**shared, **options}.items()
        ]
    )
    command.__annotations__ = {name: cls for name, (cls, _) in {**shared, **options}.items()}
    app = typer.Typer(add_completion=False, rich_markup_mode="markdown")
    app.command(cls=Command, help=(stage.__doc__ or "").split("\n\n")[0])(command)
    app(prog_name=f"python -m {module}")


def load_stage_params(path: Path | None, stage):
    """The params ``stage`` (a stage module) reads from the file at ``path`` (a bad one: ParamsError, exit 2; None: the
    built-in defaults)."""
    return load_params(path, stage.Params)
