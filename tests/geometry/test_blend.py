"""The blend pool's geometric interpolation (graspaug.geometry.blend) on closed meshes."""

import numpy as np
import pytest
import trimesh

from graspaug.geometry.blend import blend_solids, signed_distance_grid
from graspaug.geometry.voxelize import fit_grid, iou, voxelize_solid

BOX = trimesh.creation.box(extents=(0.06, 0.03, 0.02))
CAPSULE = trimesh.creation.capsule(height=0.03, radius=0.012)  # 5.4 cm long along z


def occupancy(mesh: trimesh.Trimesh, frame: trimesh.Trimesh) -> np.ndarray:
    """``mesh``'s voxels in the 32³ grid fit to ``frame``, its bounding box centered as ``frame``'s."""
    shift = frame.bounds.mean(axis=0) - mesh.bounds.mean(axis=0)
    return voxelize_solid(mesh.vertices + shift, mesh.faces, fit_grid(frame.bounds, 32, 1))


@pytest.mark.parametrize("alpha, parent", [(0.0, BOX), (1.0, CAPSULE)])
def test_a_blend_at_either_end_is_that_parent(alpha, parent):
    child, reason = blend_solids(BOX, CAPSULE, alpha, 96, 3)
    assert reason is None and child.is_watertight
    assert iou(occupancy(child, parent), occupancy(parent, parent)) >= 0.95
    np.testing.assert_allclose(child.extents, parent.extents, atol=2 * 0.06 / 90)  # within two cells of 0.67 mm


def test_a_midway_blend_lies_between_its_parents_in_shape_and_size():
    small = trimesh.creation.box(extents=(0.02, 0.02, 0.02))
    large = trimesh.creation.box(extents=(0.06, 0.06, 0.06))
    child, reason = blend_solids(small, large, 0.5, 64, 2)
    assert reason is None
    np.testing.assert_allclose(child.extents, 0.04, rtol=0.05)  # cubes aligned as their grids: the mean size
    mixed, _ = blend_solids(BOX, CAPSULE, 0.5, 64, 2)
    to_box, to_capsule = (iou(occupancy(mixed, m), occupancy(m, m)) for m in (BOX, CAPSULE))
    assert 0.3 < to_box < 0.95 and 0.3 < to_capsule < 0.95  # neither parent


def test_the_signed_distance_changes_sign_at_the_surface():
    field, pitch = signed_distance_grid(BOX, 40, 2)
    assert pitch == pytest.approx(0.06 / 36)
    assert field[20, 20, 20] < 0 < field[0, 0, 0]  # the center is inside, the corner outside
    inside = field < 0
    np.testing.assert_array_equal(inside, voxelize_solid(BOX.vertices, BOX.faces, fit_grid(BOX.bounds, 40, 2)))
