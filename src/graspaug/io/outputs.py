"""Output folders of the user's commands: a command replaces only the files it wrote itself.

A command that writes a folder records the files it wrote in a manifest, :data:`MARKER` (JSON: ``written_by``,
``graspaug <command>``, and ``files``, each path relative to the folder → the sha256 of the bytes written). A file is
the command's only while the manifest lists its name, the name stays inside the folder (no ``..``, not absolute), no
folder on its way is a symbolic link, and its bytes still hash as written; any other file is the user's.

Before any work :func:`check_output_folder` refuses, in one line naming the culprit: an output folder that is a
symbolic link or a file, that is, holds or lies inside one of the command's inputs, that is or holds the working
folder (or another folder the caller names, such as the project), or that cannot be written (even with ``force``);
and, unless ``force``, a folder holding any file that is not the command's (a file the user added or saved over one
the command wrote, another command's, or any file of a folder no manifest vouches for).

:func:`output_folder` stages what the command writes in a temporary sibling of the folder and moves the files in
only when all are written, so a failure or an interrupt leaves the folder as it was. A new folder appears whole
(one rename); into an existing one the new files are moved one by one, the command's files of the previous run that
this run does not write are removed, and every other file is left in place (one the user changed since is named in
the log). ``force`` lets a command write beside files it did not write, replacing those of the names it writes; it
never deletes any other, and never writes through a symbolic link.
"""

from __future__ import annotations

import contextlib
import errno
import hashlib
import json
import logging
import os
import shutil
import stat
import tempfile
from collections.abc import Iterable, Iterator
from pathlib import Path, PurePosixPath

from graspaug.errors import DataError
from graspaug.io.atomic import atomic_path, remove_stale_temporaries
from graspaug.io.digest import sha256_of

log = logging.getLogger(__name__)

#: The manifest of a folder written by a graspaug command (JSON: ``written_by``, ``files``: name → sha256). Older
#: versions listed the names alone (such a file is the command's by name, and is never deleted) or wrote one line,
#: ``graspaug <command>``, and no list (such a folder's files count as not written by the command).
MARKER = ".graspaug-output"


def _inside(name: str) -> bool:
    """Whether the manifest name ``name`` is a relative ``/``-separated path that stays inside its folder."""
    return "\\" not in name and all(part not in ("", ".", "..") for part in name.split("/"))  # "/x": "" first


def _manifest(folder: Path) -> dict:
    """The manifest of ``folder``: ``written_by`` and ``files`` (name → sha256, or None for an older list), the names
    that leave the folder dropped; empty when there is none, or it is a symbolic link or not JSON."""
    marker = folder / MARKER
    if not marker.is_file() or marker.is_symlink():
        return {}
    text = marker.read_text(errors="replace")
    try:
        manifest = json.loads(text)
    except ValueError:
        return {"written_by": text.strip()} if text.startswith("graspaug ") else {}  # an older one-line marker
    if not isinstance(manifest, dict):
        return {}
    files = manifest.get("files", {})
    listed = files if isinstance(files, dict) else dict.fromkeys(files if isinstance(files, list) else [])
    return {**manifest, "files": {str(k): v for k, v in listed.items() if isinstance(k, str) and _inside(k)}}


def plain_file(folder: str | os.PathLike, name: str) -> Path | None:
    """``folder / name`` when it is a regular file reached through real folders only (no symbolic link on the way,
    itself not one) and ``name`` stays inside ``folder``; else None."""
    if not _inside(name):
        return None
    path = Path(folder)
    for part in PurePosixPath(name).parts:
        path = path / part
        try:
            mode = os.lstat(path).st_mode
        except OSError:
            return None
        if stat.S_ISLNK(mode):
            return None
    return path if stat.S_ISREG(mode) else None


def made_by(folder: str | os.PathLike) -> str | None:
    """The command that wrote ``folder`` (``"graspaug <command>"``), or None when it carries no manifest."""
    return _manifest(Path(folder)).get("written_by")


def _listed(folder: Path, command: str) -> dict[str, str | None]:
    manifest = _manifest(folder)
    return manifest.get("files", {}) if manifest.get("written_by") == f"graspaug {command}" else {}


def _is_ours(folder: Path, name: str, digest: str | None) -> bool:
    path = plain_file(folder, name)
    return path is not None and (digest is None or sha256_of(path) == digest)


def owned_files(folder: str | os.PathLike, command: str) -> set[str]:
    """The files (paths relative to ``folder``, ``/``-separated) that are ``graspaug <command>``'s now: its manifest
    lists them, they lie inside ``folder`` without a symbolic link on the way, and their bytes are those it wrote."""
    folder = Path(folder)
    return {name for name, digest in _listed(folder, command).items() if _is_ours(folder, name, digest)}


def held_files(folder: str | os.PathLike) -> list[str]:
    """Every file (and symbolic link, never followed) under ``folder``, as sorted paths relative to it, the manifest
    left out; empty folders are not listed (nothing is lost with them)."""
    folder = Path(folder)
    held = []
    for root, dirs, names in os.walk(folder):
        held += [Path(root, n).relative_to(folder).as_posix() for n in names]
        held += [Path(root, n).relative_to(folder).as_posix() for n in dirs if os.path.islink(os.path.join(root, n))]
    return sorted(name for name in held if name != MARKER)


def mark(folder: str | os.PathLike, command: str, files: dict[str, str | None] | None = None) -> None:
    """Write the manifest of ``folder``: written by ``graspaug <command>``, holding ``files`` (relative path →
    sha256; default: every file now under ``folder``, hashed)."""
    folder = Path(folder)
    if files is None:
        files = {name: sha256_of(folder / name) for name in held_files(folder)}
    with atomic_path(folder / MARKER) as tmp:
        text = json.dumps({"written_by": f"graspaug {command}", "files": dict(sorted(files.items()))}, indent=1)
        tmp.write_text(text + "\n")


def _shown(names: list[str]) -> str:
    return ", ".join(names[:3]) + (f" and {len(names) - 3} more" if len(names) > 3 else "")


def _check_writable(folder: Path, out: Path) -> None:
    """Raise :class:`DataError` naming ``out`` unless a file can be made in ``folder`` (or in its nearest existing
    parent, where the command would make it): a read-only or foreign folder is refused before any work."""
    while not folder.exists() and folder != folder.parent:
        folder = folder.parent
    if not folder.is_dir():  # a file where a folder of the path belongs (--out afile/sub)
        raise DataError(f"the output folder {out} cannot be made: {folder} is a file, not a folder; choose another")
    try:
        fd, probe = tempfile.mkstemp(prefix=".graspaug-probe-", dir=folder)
    except OSError as exc:
        if exc.errno not in (errno.EACCES, errno.EPERM, errno.EROFS):
            raise
        raise DataError(
            f"the output folder {out} cannot be written: {folder} refuses new files ({exc.strerror.lower()}); "
            "choose another folder"
        ) from None
    os.close(fd)
    os.unlink(probe)


def check_output_folder(
    out: str | os.PathLike,
    command: str,
    inputs: Iterable[str | os.PathLike | None] = (),
    force: bool = False,
    homes: Iterable[tuple[str, str | os.PathLike]] = (),
) -> None:
    """Raise :class:`DataError` (one line, naming the folder and the culprit) unless ``graspaug <command>`` may
    write ``out``; call it before any work.

    ``out`` may be missing, empty, or hold only the command's files (see the module's text); with ``force``, other
    files too (they are kept). It may never be a symbolic link or a file, nor be, hold or lie inside a file or folder
    of ``inputs`` (None entries are skipped), nor be or hold the working folder or a folder of ``homes`` (pairs of
    what it is, e.g. ``"the project"``, and its path), and it must be writable.
    """
    out = Path(out)
    if out.is_symlink():
        raise DataError(
            f"the output folder {out} is a symbolic link (to {os.readlink(out)}); give the folder itself, or a new one"
        )
    target = out.resolve()
    for what, folder in [("the working folder", Path.cwd()), *homes]:
        home = Path(folder).resolve()
        if target == home or target in home.parents:
            raise DataError(
                f"the output folder {out} {'is' if target == home else 'holds'} {what} ({folder}); choose a folder "
                "inside it or elsewhere"
            )
    for folder in inputs:
        if folder is None:
            continue
        source = Path(folder).resolve()
        if target == source or source in target.parents or target in source.parents:
            where = "is" if target == source else "lies inside" if source in target.parents else "holds"
            raise DataError(
                f"the output folder {out} {where} the input {folder}: writing it could delete the input; "
                "choose an output folder outside it"
            )
    if out.exists() and not out.is_dir():
        raise DataError(f"the output folder {out} is a file; give a folder")
    _check_writable(target.parent, out)  # the staging folder is made beside it
    if out.exists():
        _check_writable(target, out)
    if force or not out.exists():
        return
    foreign = sorted(set(held_files(out)) - owned_files(out, command))
    if foreign:
        raise DataError(
            f"the output folder {out} holds {_shown(foreign)}, which graspaug {command} did not write (or which "
            f"changed since); move {'it' if len(foreign) == 1 else 'them'} away or choose another folder, or pass "
            "--force to write beside them (files of other names are kept)"
        )


def _way_in(out: Path, name: str) -> str | None:
    """The first path on the way to ``out / name`` (relative to ``out``) that is a symbolic link, or a file where a
    folder belongs; None when the way is clear."""
    parts = PurePosixPath(name).parts
    for i in range(1, len(parts) + 1):
        path = out.joinpath(*parts[:i])
        if path.is_symlink() or (i < len(parts) and path.exists() and not path.is_dir()):
            return "/".join(parts[:i])
    return None


def _commit(staging: Path, out: Path, command: str, force: bool) -> list[str]:
    """Move the files of ``staging`` into ``out`` (see the module's text); returns the files written."""
    new = {name: sha256_of(staging / name) for name in held_files(staging)}
    if not out.exists():
        mark(staging, command, new)
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(staging, 0o777 & ~umask)  # mkdtemp makes it owner-only
        os.replace(staging, out)
        return list(new)
    listed = _listed(out, command)
    ours = {name: digest for name, digest in listed.items() if _is_ours(out, name, digest)}
    blocked = sorted({way for way in map(lambda n: _way_in(out, n), new) if way is not None})
    if blocked:
        raise DataError(
            f"the output folder {out} holds {_shown(blocked)} as a symbolic link or a file where graspaug {command} "
            "writes a folder's files; nothing was written: move it away"
        )
    clash = [name for name in new if name not in ours and os.path.lexists(out / name)]
    if clash and not force:  # a file of these names appeared (or changed) while the command ran
        raise DataError(
            f"the output folder {out} now holds {_shown(clash)}, which graspaug {command} did not write; nothing "
            "was written: move it away, or pass --force to replace it"
        )
    mark(out, command, {**ours, **new})  # an interrupt from here on leaves only files the manifest calls ours
    for name in new:
        (out / name).parent.mkdir(parents=True, exist_ok=True)
        os.replace(staging / name, out / name)
    for name in sorted(set(listed) - set(new)):
        if name not in ours:
            if os.path.lexists(out / name):
                log.info("kept %s: it changed since graspaug %s wrote it, so it is yours now", out / name, command)
            continue
        stale = out / name
        stale.unlink()
        for parent in stale.parents:  # folders the previous run made and left empty
            if parent == out or not parent.is_dir() or any(parent.iterdir()):
                break
            parent.rmdir()
    mark(out, command, new)
    shutil.rmtree(staging, ignore_errors=True)
    return list(new)


@contextlib.contextmanager
def output_folder(
    out: str | os.PathLike,
    command: str,
    inputs: Iterable[str | os.PathLike | None] = (),
    force: bool = False,
    homes: Iterable[tuple[str, str | os.PathLike]] = (),
) -> Iterator[Path]:
    """Check ``out`` (:func:`check_output_folder`), yield an empty staging folder to write the command's files
    into, and when the block ends without error move them into ``out`` and list them in its manifest; the command's
    files of the last run that it does not write now are removed, no other file is touched. On an error (or an
    interrupt) ``out`` is left as it was and the staging folder removed (a killed process leaves it as a ``.tmp-*``
    sibling of ``out`` that the next run removes). Two commands writing into one ``out`` take turns: the second
    waits (logging that it does) until the first has finished, then writes over the first's files as its own."""
    from graspaug.io.atomic import exclusive_lock

    inputs, homes = list(inputs), list(homes)
    out = Path(out)
    check_output_folder(out, command, inputs, force, homes)
    where = out.absolute()
    where.parent.mkdir(parents=True, exist_ok=True)
    key = hashlib.sha256(str(where).encode()).hexdigest()[:16]  # the lock lives outside the user's folders
    with exclusive_lock(Path(tempfile.gettempdir()) / "graspaug-locks" / f"out-{key}.lock"):  # a second one waits
        check_output_folder(out, command, inputs, force, homes)  # as the first one left it
        remove_stale_temporaries(where)
        staging = Path(tempfile.mkdtemp(prefix=f".{where.name}.tmp-", dir=where.parent))
        try:
            yield staging
            check_output_folder(out, command, inputs, True, homes)  # still not a link, a file or an input
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
