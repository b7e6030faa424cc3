"""Per-shape loops (and a seed's networks): joblib worker processes with a tqdm progress bar, on this
machine or on a Dask distributed cluster.

``Workers(executor="dask", scheduler="tcp://host:8786")`` sends the same calls through joblib's
``dask`` backend to the cluster behind that scheduler; its workers must import graspaug and see
the project folder at the same path (a shared filesystem), as the functions read and write the
files of their shape. Results come back in order either way, so outputs do not depend on where
they were computed.
"""

from __future__ import annotations

import contextlib
import os
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any, TypeVar

from joblib import Parallel, delayed, parallel_config
from tqdm import tqdm

from graspaug.device import release_freed_memory

T = TypeVar("T")


@dataclass(frozen=True)
class Workers:
    """Where per-shape work runs: ``n_jobs`` local processes (``executor="joblib"``; -1: all
    cores), or a Dask cluster (``executor="dask"``) reached at ``scheduler``."""

    n_jobs: int = 1
    executor: str = "joblib"
    scheduler: str | None = None

    def __post_init__(self) -> None:
        if self.executor not in ("joblib", "dask"):
            raise ValueError(f"executor must be joblib or dask, got {self.executor!r}")
        if self.executor == "dask" and not self.scheduler:
            raise ValueError("executor dask needs a scheduler address (e.g. tcp://10.0.0.5:8786)")


@contextlib.contextmanager
def _dask_backend(scheduler: str):
    try:
        from dask.distributed import Client
    except ImportError:
        raise RuntimeError("executor: dask needs Dask's distributed scheduler: pip install 'graspaug[dask]'") from None
    with Client(scheduler), parallel_config(backend="dask"):
        yield


def _in_folder(folder: str, fn: Callable[..., T], item: Any) -> T:
    """``fn(item)`` with the working folder set to ``folder`` (a cluster worker resolves the
    stage's relative paths as the submitting process does)."""
    os.chdir(folder)
    return fn(item)


_LEAK_GUARD = 2 << 30  # bytes


def _relax_leak_guard() -> None:
    """Raise loky's leak guard in this worker process from 300 MB to 2 GiB. A worker's resident size
    also grows by what it legitimately keeps: libraries loaded on a shape's first use of them,
    caches, a larger mesh's pages that glibc could not hand back; loky would read that as a leak
    after one large shape. loky reads the limit, a module global, at every check."""
    try:
        from joblib.externals.loky import process_executor
    except ImportError:
        return
    process_executor._MAX_MEMORY_LEAK_SIZE = max(getattr(process_executor, "_MAX_MEMORY_LEAK_SIZE", 0), _LEAK_GUARD)


def _trimmed(fn: Callable[..., T], item: Any) -> T:
    """``fn(item)`` in a worker process, then :func:`graspaug.device.release_freed_memory` (glibc keeps what a
    large mesh or scene freed; joblib's loky executor restarts a worker grown 300 MB past its size after its
    first task, with a warning); the worker's leak guard relaxed (:func:`_relax_leak_guard`)."""
    _relax_leak_guard()
    try:
        return fn(item)
    finally:
        release_freed_memory()


def parallel_map(
    fn: Callable[..., T],
    items: Sequence[Any],
    workers: int | Workers,
    desc: str,
    unit: str = "shape",
    batch_size: int | str = "auto",
) -> list[T]:
    """``[fn(item) for item in items]`` on ``workers`` (a process count or :class:`Workers`), in
    order, with a progress bar ``desc`` counting ``unit``s. One local job (or one item) runs here, in
    this process; otherwise calls go to the workers ``batch_size`` at a time (joblib's ``auto`` groups
    calls that finish in well under a second; 1: one call per task)."""
    workers = workers if isinstance(workers, Workers) else Workers(n_jobs=workers)
    results: list[T] = []
    with tqdm(total=len(items), desc=desc, unit=unit, dynamic_ncols=True) as bar:
        if workers.executor == "joblib" and (workers.n_jobs == 1 or len(items) <= 1):
            for item in items:
                results.append(fn(item))
                bar.update()
            return results
        if workers.executor == "dask":
            backend, n_jobs, calls = (
                _dask_backend(workers.scheduler),
                -1,
                (delayed(_in_folder)(os.getcwd(), fn, item) for item in items),
            )
        else:
            backend, n_jobs = contextlib.nullcontext(), workers.n_jobs
            calls = (delayed(_trimmed)(fn, item) for item in items)
        with backend:
            for result in Parallel(n_jobs=n_jobs, return_as="generator", batch_size=batch_size)(calls):
                results.append(result)
                bar.update()
    return results
