"""A closed one-body mesh is kept whole: the "in pieces" rule is for solids that really fall apart."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

from graspaug.geometry.loading import load_shape
from graspaug.geometry.prepare import prepare_shape
from graspaug.geometry.settings import SurfaceSettings


@pytest.mark.parametrize("size", ["real", "normalize"])
def test_a_watertight_pyramid_is_kept_in_one_piece(tmp_path, size):
    """The issue's ``contactdb/pyramid_small.stl``: 5 vertices, watertight, 21 cm³, rejected as "in pieces: 80% of
    the volume lies outside the largest piece" (its faces pass through the field's samples)."""
    base, height = 0.04, 0.04
    vertices = np.array([[0, 0, 0], [base, 0, 0], [base, base, 0], [0, base, 0], [base / 2, base / 2, height]])
    faces = np.array([[0, 2, 1], [0, 3, 2], [0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]])
    pyramid = trimesh.Trimesh(vertices, faces)
    assert pyramid.is_watertight and len(pyramid.vertices) == 5
    pyramid.export(tmp_path / "pyramid_small.stl")
    prepared = prepare_shape(load_shape(tmp_path / "pyramid_small.stl"), SurfaceSettings(size=size))
    assert prepared.dropped_volume == 0 and prepared.mesh.is_watertight and prepared.mesh.body_count == 1
    if size == "real":
        assert prepared.mesh.volume == pytest.approx(base * base * height / 3, rel=0.02)  # 21.3 cm³
        assert np.allclose(np.sort(prepared.mesh.extents), [base, base, height], atol=0.001)
