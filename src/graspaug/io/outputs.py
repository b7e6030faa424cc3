"""Output folders of the user's commands: a command replaces only the files it wrote itself.

A command that writes a folder records the files it wrote in a manifest, :data:`MARKER` (JSON: ``written_by``,
``graspaug <command>``, and ``files``, their paths relative to the folder). Before any work
:func:`check_output_folder` refuses, in one line naming the culprit: an output folder that is a symbolic link or a
file, or that is, holds or lies inside one of the command's input folders (even with ``force``); and, unless
``force``, a folder holding any file that the manifest of the same command does not list (a file the user added
after the last run, another command's, or any file of a folder no manifest vouches for).

:func:`output_folder` stages what the command writes in a temporary sibling of the folder and moves the files in
only when all are written, so a failure or an interrupt leaves the folder as it was. A new folder appears whole
(one rename); into an existing one the new files are moved one by one, the files of the previous run that this run
does not write are removed, and every other file is left in place. ``force`` lets a command write beside files it
did not write, replacing those of the names it writes; it never deletes any other.
"""

from __future__ import annotations

import contextlib
import json
import os
import shutil
import tempfile
from collections.abc import Iterable, Iterator
from pathlib import Path

from graspaug.errors import DataError
from graspaug.io.atomic import atomic_path, remove_stale_temporaries

#: The manifest of a folder written by a graspaug command (JSON: ``written_by``, ``files``). Older versions wrote
#: one line, ``graspaug <command>``, and no list: such a folder's files count as not written by the command.
MARKER = ".graspaug-output"


def _manifest(folder: Path) -> dict:
    marker = folder / MARKER
    if not marker.is_file() or marker.is_symlink():
        return {}
    text = marker.read_text(errors="replace")
    try:
        manifest = json.loads(text)
    except ValueError:
        return {"written_by": text.strip()} if text.startswith("graspaug ") else {}  # an older one-line marker
    return manifest if isinstance(manifest, dict) else {}


def made_by(folder: str | os.PathLike) -> str | None:
    """The command that wrote ``folder`` (``"graspaug <command>"``), or None when it carries no manifest."""
    return _manifest(Path(folder)).get("written_by")


def owned_files(folder: str | os.PathLike, command: str) -> set[str]:
    """The files (paths relative to ``folder``, ``/``-separated) that ``graspaug <command>`` wrote into ``folder``
    by its manifest; empty when another command, or none, wrote the manifest."""
    manifest = _manifest(Path(folder))
    if manifest.get("written_by") != f"graspaug {command}":
        return set()
    return {str(name) for name in manifest.get("files", [])}


def held_files(folder: str | os.PathLike) -> list[str]:
    """Every file (and symbolic link) under ``folder``, as sorted paths relative to it, the manifest left out;
    empty folders are not listed (nothing is lost with them)."""
    folder = Path(folder)
    held = [p.relative_to(folder).as_posix() for p in folder.rglob("*") if p.is_symlink() or not p.is_dir()]
    return sorted(name for name in held if name != MARKER)


def mark(folder: str | os.PathLike, command: str, files: Iterable[str] | None = None) -> None:
    """Write the manifest of ``folder``: written by ``graspaug <command>``, holding ``files`` (relative paths;
    default: every file now under ``folder``)."""
    folder = Path(folder)
    names = sorted(held_files(folder) if files is None else set(files))
    with atomic_path(folder / MARKER) as tmp:
        tmp.write_text(json.dumps({"written_by": f"graspaug {command}", "files": names}, indent=1) + "\n")


def _shown(names: list[str]) -> str:
    return ", ".join(names[:3]) + (f" and {len(names) - 3} more" if len(names) > 3 else "")


def check_output_folder(
    out: str | os.PathLike, command: str, inputs: Iterable[str | os.PathLike | None] = (), force: bool = False
) -> None:
    """Raise :class:`DataError` (one line, naming the folder and the culprit) unless ``graspaug <command>`` may
    write ``out``; call it before any work.

    ``out`` may be missing, empty, or hold only files the command's manifest lists; with ``force``, other files
    too (they are kept). It may never be a symbolic link or a file, nor be, hold or lie inside a folder of
    ``inputs`` (None entries are skipped).
    """
    out = Path(out)
    if out.is_symlink():
        raise DataError(
            f"the output folder {out} is a symbolic link (to {os.readlink(out)}); give the folder itself, or a new one"
        )
    target = out.resolve()
    for folder in inputs:
        if folder is None:
            continue
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
    if force:
        return
    foreign = sorted(set(held_files(out)) - owned_files(out, command))
    if foreign:
        raise DataError(
            f"the output folder {out} holds {_shown(foreign)}, which graspaug {command} did not write; move "
            f"{'it' if len(foreign) == 1 else 'them'} away or choose another folder, or pass --force to write "
            "beside them (files of other names are kept)"
        )


def _commit(staging: Path, out: Path, command: str, force: bool) -> list[str]:
    """Move the files of ``staging`` into ``out`` (see the module's text); returns the files written."""
    new = held_files(staging)
    if not out.exists():
        mark(staging, command, new)
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(staging, 0o777 & ~umask)  # mkdtemp makes it owner-only
        os.replace(staging, out)
        return new
    old = owned_files(out, command)
    clash = [name for name in new if name not in old and ((out / name).exists() or (out / name).is_symlink())]
    if clash and not force:  # a file of these names appeared while the command ran
        raise DataError(
            f"the output folder {out} now holds {_shown(clash)}, which graspaug {command} did not write; nothing "
            "was written: move it away, or pass --force to replace it"
        )
    mark(out, command, old | set(new))  # an interrupt from here on leaves only files the manifest calls ours
    for name in new:
        (out / name).parent.mkdir(parents=True, exist_ok=True)
        os.replace(staging / name, out / name)
    for name in sorted(old - set(new)):
        stale = out / name
        stale.unlink(missing_ok=True)
        for parent in stale.parents:  # folders the previous run made and left empty
            if parent == out or not parent.is_dir() or any(parent.iterdir()):
                break
            parent.rmdir()
    mark(out, command, new)
    shutil.rmtree(staging, ignore_errors=True)
    return new


@contextlib.contextmanager
def output_folder(
    out: str | os.PathLike, command: str, inputs: Iterable[str | os.PathLike | None] = (), force: bool = False
) -> Iterator[Path]:
    """Check ``out`` (:func:`check_output_folder`), yield an empty staging folder to write the command's files
    into, and when the block ends without error move them into ``out`` and list them in its manifest; the files
    the command wrote last time and not now are removed, no other file is touched. On an error (or an interrupt)
    ``out`` is left as it was and the staging folder removed (a killed process leaves it as a ``.tmp-*`` sibling
    of ``out`` that the next run removes)."""
    inputs = list(inputs)
    out = Path(out)
    check_output_folder(out, command, inputs, force)
    where = out.absolute()
    where.parent.mkdir(parents=True, exist_ok=True)
    remove_stale_temporaries(where)
    staging = Path(tempfile.mkdtemp(prefix=f".{where.name}.tmp-", dir=where.parent))
    try:
        yield staging
        check_output_folder(out, command, inputs, force=True)  # still not a link, a file or an input
        _commit(staging, where, command, force)
    finally:
        if staging.exists():
            shutil.rmtree(staging, ignore_errors=True)


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
