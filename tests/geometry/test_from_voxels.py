"""Decoded grids to meshes: cleaning with reasons, closed meshes in meters."""

import numpy as np
import pytest

from graspaug.geometry.from_voxels import clean_occupancy, mesh_from_occupancy

R = 32
CENTERS = np.indices((R, R, R)).transpose(1, 2, 3, 0) + 0.5


def ball(center, radius):
    return (np.linalg.norm(CENTERS - np.asarray(center), axis=-1) < radius).astype(np.float32)


def test_sphere_grid_becomes_a_closed_sphere_in_meters():
    grid = clean_occupancy(0.9 * ball((16, 16, 16), 10), 0.5, 1, 20, 0.9)
    assert grid.reason is None and grid.main_share == 1.0
    mesh = mesh_from_occupancy(grid.occupancy, pitch=0.002, smoothing_iterations=10)
    assert mesh.is_watertight and len(mesh.split()) == 1
    assert mesh.volume == pytest.approx(4 / 3 * np.pi * 0.02**3, rel=0.05)
    np.testing.assert_allclose(mesh.center_mass, 0, atol=1e-12)
    assert mesh.extents == pytest.approx([0.04] * 3, rel=0.05)


def test_torus_keeps_its_hole():
    u = CENTERS - 16
    ring = np.hypot(np.hypot(u[..., 0], u[..., 1]) - 9, u[..., 2]) < 4
    mesh = mesh_from_occupancy(clean_occupancy(ring.astype(float), 0.5, 1, 20, 0.9).occupancy, 0.001, 10)
    assert mesh.is_watertight and mesh.euler_number == 0


def test_degenerate_decodes_are_rejected_with_reasons():
    assert clean_occupancy(np.full((R, R, R), 0.2), 0.5, 1, 20, 0.9).reason == "empty decode"
    assert clean_occupancy(ball((16, 16, 16), 2.5), 0.5, 0, 100, 0.9).reason.startswith("tiny:")
    two = np.maximum(ball((8, 16, 16), 5), ball((24, 16, 16), 5))
    result = clean_occupancy(two, 0.5, 1, 20, 0.9)
    assert result.reason == "in pieces: the largest of 2 holds 50% of the voxels"


def test_cleaning_fills_cavities_and_drops_spurs():
    solid = ball((16, 16, 16), 9) - ball((16, 16, 16), 4)  # a hollow ball ...
    solid[16, 16, 25:31] = 1  # ... with a one-voxel spur
    grid = clean_occupancy(solid, 0.5, 1, 20, 0.9)
    assert grid.occupancy[16, 16, 16] and not grid.occupancy[16, 16, 29]
