"""Per-shape loops: joblib worker processes with a tqdm progress bar."""
from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any, TypeVar

from joblib import Parallel, delayed
from tqdm import tqdm

T = TypeVar("T")


def parallel_map(fn: Callable[..., T], items: Sequence[Any], n_jobs: int, desc: str) -> list[T]:
    """``[fn(item) for item in items]`` on ``n_jobs`` processes, in order, with a progress bar."""
    results: list[T] = []
    with tqdm(total=len(items), desc=desc, unit="shape", dynamic_ncols=True) as bar:
        if n_jobs == 1 or len(items) <= 1:
            for item in items:
                results.append(fn(item))
                bar.update()
        else:
            run = Parallel(n_jobs=n_jobs, return_as="generator", batch_size="auto")
            for result in run(delayed(fn)(item) for item in items):
                results.append(result)
                bar.update()
    return results
