"""Output folders of the user's commands: a command replaces or fills only a folder it made itself.

A folder a command writes gets a marker file, :data:`MARKER`, naming the command. Before writing,
:func:`check_output_folder` refuses a folder that exists, holds anything, and carries no marker of
the same command (unless ``force``), and always refuses an output folder that is, holds or lies
inside one of the command's input folders: replacing it would delete what the command was asked
to read.
"""

from __future__ import annotations

import os
from collections.abc import Iterable
from pathlib import Path

from graspaug.errors import DataError

#: The file that marks a folder as written by a graspaug command (its text: ``graspaug <command>``).
MARKER = ".graspaug-output"


def made_by(folder: str | os.PathLike) -> str | None:
    """The command that wrote ``folder`` (``"graspaug <command>"``), or None when it carries no marker."""
    marker = Path(folder) / MARKER
    return marker.read_text().strip() if marker.is_file() else None


def mark(folder: str | os.PathLike, command: str) -> None:
    """Mark ``folder`` as written by ``graspaug <command>``."""
    (Path(folder) / MARKER).write_text(f"graspaug {command}\n")


def check_output_folder(
    out: str | os.PathLike, command: str, inputs: Iterable[str | os.PathLike] = (), force: bool = False
) -> None:
    """Raise :class:`DataError` (one line, naming the folder) unless ``graspaug <command>`` may write ``out``.

    ``out`` may be missing, an empty folder, or a folder that the same command marked; with ``force``
    any folder. It may never be a file, nor be, hold or lie inside a folder of ``inputs``.
    """
    out = Path(out)
    target = out.resolve()
    for folder in inputs:
        source = Path(folder).resolve()
        if target == source or source in target.parents or target in source.parents:
            where = "is" if target == source else "lies inside" if source in target.parents else "holds"
            raise DataError(
                f"the output folder {out} {where} the input folder {folder}: writing it would delete the input; "
                "choose an output folder outside it"
            )
    if not out.exists():
        return
    if not out.is_dir():
        raise DataError(f"the output folder {out} is a file; give a folder")
    held = sorted(p.name for p in out.iterdir())
    if not held or force or made_by(out) == f"graspaug {command}":
        return
    shown = ", ".join(held[:3]) + (f" and {len(held) - 3} more" if len(held) > 3 else "")
    raise DataError(
        f"the output folder {out} already holds files that graspaug {command} did not write ({shown}); "
        "choose a new folder, or pass --force to replace them"
    )


def check_output_files(
    out: str | os.PathLike, names: Iterable[str], command: str, owned: str, force: bool = False
) -> None:
    """Raise :class:`DataError` unless ``graspaug <command>`` may write the files ``names`` into the folder ``out``:
    ``out`` must not be a file, and each file of ``names`` that exists must be one the command wrote, as told by the
    first of ``names`` holding the text ``owned`` (a command writing into a folder it does not own, such as the
    current one, marks its files, not the folder); with ``force`` any file is replaced."""
    out, names = Path(out), list(names)
    if out.exists() and not out.is_dir():
        raise DataError(f"--out {out} is a file; give a folder (it is made if missing)")
    present = [name for name in names if (out / name).exists()]
    if force or not present:
        return
    first = out / names[0]
    ours = first.is_file() and owned in first.read_text(errors="replace")[:10_000]
    if not ours:
        raise DataError(
            f"{out} already holds {', '.join(present)}, not written by graspaug {command}; choose another --out, "
            "or pass --force to replace them"
        )
