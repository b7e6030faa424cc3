"""Meshes for the render tests: primitives and real objects from pybullet_data."""

from __future__ import annotations

import pybullet_data
import pytest
import trimesh


def _pybullet_mesh(relative: str, size: float = 0.08) -> trimesh.Trimesh:
    """A pybullet_data mesh scaled so its largest extent is ``size`` m, center of mass at the origin."""
    mesh = trimesh.load(f"{pybullet_data.getDataPath()}/{relative}", force="mesh")
    mesh.apply_scale(size / mesh.extents.max())
    mesh.apply_translation(-(mesh.center_mass if mesh.is_volume else mesh.centroid))
    return mesh


@pytest.fixture(scope="session")
def duck() -> trimesh.Trimesh:
    return _pybullet_mesh("duck.obj")


@pytest.fixture(scope="session")
def random_object() -> trimesh.Trimesh:
    return _pybullet_mesh("random_urdfs/000/000.obj")
