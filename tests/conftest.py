"""Shared fixtures: real meshes from trimesh primitives and pybullet_data."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

os.environ.setdefault("DVC_NO_ANALYTICS", "1")

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
