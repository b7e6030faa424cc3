"""Atomic writes: a file or folder appears under its final name complete, or not at all; and the lock that keeps two
writers of one shared folder (a cache entry) apart."""

from __future__ import annotations

import contextlib
import glob
import logging
import os
import shutil
import tempfile
from collections.abc import Iterable, Iterator
from pathlib import Path


def remove_stale_temporaries(path: str | os.PathLike) -> None:
    """Delete the ``.tmp-*`` siblings of ``path`` that a killed writer left behind (DVC runs one
    stage at a time per workspace, so no other writer of ``path`` is alive)."""
    path = Path(path)
    for stale in path.parent.glob(f".{glob.escape(path.name)}.tmp-*"):
        if stale.is_dir():
            shutil.rmtree(stale, ignore_errors=True)
        else:
            stale.unlink(missing_ok=True)


@contextlib.contextmanager
def atomic_path(path: str | os.PathLike, directory: bool = False) -> Iterator[Path]:
    """Yield a temporary sibling of ``path`` to write into; move it over ``path`` on success.

    If the block raises (or the process dies) the final name is untouched and the
    temporary is removed (or, if the process was killed, left as a ``.tmp-*`` sibling that no
    reader takes and the next write of ``path`` removes).
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    remove_stale_temporaries(path)
    if directory:
        tmp = Path(tempfile.mkdtemp(prefix=f".{path.name}.tmp-", dir=path.parent))
    else:
        fd, name = tempfile.mkstemp(prefix=f".{path.name}.tmp-", suffix=path.suffix, dir=path.parent)
        os.close(fd)
        tmp = Path(name)
    try:
        yield tmp
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, (0o777 if directory else 0o666) & ~umask)  # mkstemp/mkdtemp make them owner-only
        if directory:
            if path.exists():
                shutil.rmtree(path)
            os.replace(tmp, path)
        else:
            os.replace(tmp, path)
    except BaseException:
        if tmp.is_dir():
            shutil.rmtree(tmp, ignore_errors=True)
        else:
            tmp.unlink(missing_ok=True)
        raise


@contextlib.contextmanager
def atomic_paths(paths: Iterable[str | os.PathLike]) -> Iterator[list[Path]]:
    """Yield a temporary sibling of each of ``paths`` (files) to write into; only when the block ends without error
    move them all over their final names, the last of ``paths`` first and the first last (so a reader that checks the
    first file, such as a ``grasp.json`` beside its ``grasp.png``, finds the others already in place). If the block
    raises, no final name is touched and every temporary is removed."""
    with contextlib.ExitStack() as stack:  # exits in reverse order: the first path is moved in last
        yield [stack.enter_context(atomic_path(path)) for path in paths]


@contextlib.contextmanager
def exclusive_lock(path: str | os.PathLike) -> Iterator[None]:
    """Hold an exclusive lock on the file ``path`` (made if missing; left in place) for the block: a second process
    asking for it waits until the first leaves the block or dies (the system frees the lock of a dead process), so two
    commands never write one cache entry at once."""
    import fcntl

    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    with open(path, "a") as f:
        try:
            fcntl.flock(f, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            logging.getLogger(__name__).info("waiting for another process to release %s", path)
            fcntl.flock(f, fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(f, fcntl.LOCK_UN)
