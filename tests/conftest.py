"""Shared fixtures: real meshes from trimesh primitives and pybullet_data."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

os.environ.setdefault("DVC_NO_ANALYTICS", "1")


def _worker_threads(workers: int) -> int:
    """One xdist worker's share of the cores: `make test` runs two workers on 2 cores, and a torch (OpenMP, BLAS)
    process with more threads than it can get waits at every parallel region for the thread the other worker holds,
    its cores spinning (a step of the tiny profile's 16³ AE: 0.012 s at 1 thread, 0.9 s at 2 beside busy processes on
    2 cores, in CPU seconds as well)."""
    cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1
    return max(1, cores // workers)


if "PYTEST_XDIST_WORKER_COUNT" in os.environ:  # an xdist worker (set before conftest loads); before torch or numpy
    for _name in ("OMP_NUM_THREADS", "MKL_NUM_THREADS", "OPENBLAS_NUM_THREADS"):  # loads: the stages inherit it
        os.environ.setdefault(_name, str(_worker_threads(int(os.environ["PYTEST_XDIST_WORKER_COUNT"]))))

REPO = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="session")
def repo_root() -> Path:
    return REPO


@pytest.fixture(scope="session")
def default_sources():
    """The first 12 objects of the default corpus (pybullet_data/random_urdfs)."""
    from graspaug.io.sources import pybullet_sources

    return pybullet_sources(limit=12)


@pytest.fixture(scope="session")
def default_loaded(default_sources):
    """(source, LoadedShape) for the first 6 default objects."""
    from graspaug.geometry.loading import load_shape

    return [(s, load_shape(s.path, s.unit_scale)) for s in default_sources[:6]]
