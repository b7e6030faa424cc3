import numpy as np
import pytest
import trimesh

from graspaug.geometry.solid import union_contains
from graspaug.geometry.voxelize import VoxelGrid, fit_grid, iou, pack_bits, unpack_bits, voxelize_solid


def occupied_volume(mesh: trimesh.Trimesh, resolution: int) -> float:
    grid = fit_grid(mesh.bounds, resolution)
    return voxelize_solid(mesh.vertices, mesh.faces, grid).sum() * grid.pitch**3


@pytest.mark.parametrize(
    ("mesh", "exact"),
    [
        (trimesh.creation.box(extents=(0.04, 0.06, 0.05)), 0.04 * 0.06 * 0.05),
        (trimesh.creation.icosphere(subdivisions=5, radius=0.03), 4 / 3 * np.pi * 0.03**3),
        (
            trimesh.creation.torus(major_radius=0.03, minor_radius=0.01, major_sections=96, minor_sections=48),
            2 * np.pi**2 * 0.03 * 0.01**2,
        ),
    ],
    ids=["box", "sphere", "torus"],
)
def test_occupied_volume_matches_the_exact_volume(mesh, exact):
    assert occupied_volume(mesh, 64) == pytest.approx(exact, rel=0.03)


def test_box_aligned_with_the_grid_is_exact():
    # a 10×10×10-voxel cube placed on voxel boundaries: exactly 1000 voxels
    grid = VoxelGrid(resolution=16, pitch=0.01, origin=np.zeros(3))
    box = trimesh.creation.box(extents=(0.1, 0.1, 0.1))
    box.apply_translation((0.08, 0.08, 0.08))
    occ = voxelize_solid(box.vertices, box.faces, grid)
    assert occ.sum() == 1000
    assert occ[3:13, 3:13, 3:13].all()


@pytest.mark.parametrize("resolution", [16, 24, 33])
def test_agrees_with_trimesh_contains_on_closed_single_bodies(resolution):
    """``contains`` is trustworthy on one closed body: the slow, obvious reference."""
    for mesh in (
        trimesh.creation.icosphere(subdivisions=3, radius=0.02),
        trimesh.creation.torus(major_radius=0.03, minor_radius=0.012),
        trimesh.creation.capsule(height=0.05, radius=0.01),
    ):
        grid = fit_grid(mesh.bounds, resolution)
        ours = voxelize_solid(mesh.vertices, mesh.faces, grid)
        ref = mesh.contains(grid.centers().reshape(-1, 3)).reshape(ours.shape)
        assert (ours != ref).sum() <= 2  # points within float eps of the surface may differ


def test_winding_does_not_matter_and_overlaps_are_a_union():
    sphere = trimesh.creation.icosphere(subdivisions=3, radius=0.02)
    grid = fit_grid(np.array([[-0.03] * 3, [0.05] * 3]), 32)
    ours = voxelize_solid(sphere.vertices, sphere.faces, grid)
    flipped = voxelize_solid(sphere.vertices, sphere.faces[:, ::-1], grid)
    assert np.array_equal(ours, flipped)
    other = sphere.copy()
    other.apply_translation((0.02, 0.02, 0.02))
    both = trimesh.util.concatenate([sphere, other])
    union = voxelize_solid(both.vertices, both.faces, grid)
    assert np.array_equal(union, ours | voxelize_solid(other.vertices, other.faces, grid))


def test_fit_grid_keeps_the_margin_and_centers():
    bounds = np.array([[0.0, -0.01, 0.0], [0.1, 0.01, 0.05]])
    grid = fit_grid(bounds, 32, margin=1)
    assert grid.pitch == pytest.approx(0.1 / 30)
    centers = grid.origin + 0.5 * 32 * grid.pitch
    assert np.allclose(centers, bounds.mean(axis=0))
    box = trimesh.creation.box(bounds=bounds)
    occ = voxelize_solid(box.vertices, box.faces, grid)
    assert not occ[0].any() and not occ[-1].any() and occ[1].any() and occ[-2].any()


def test_pack_roundtrip():
    rng = np.random.default_rng(0)
    occ = rng.random((3, 16, 16, 16)) > 0.5
    packed = pack_bits(occ)
    assert packed.shape == (3, 16**3 // 8) and packed.dtype == np.uint8
    assert np.array_equal(unpack_bits(packed, 16), occ)


def test_iou_on_real_default_shapes_against_half_spaces(default_loaded):
    """The accuracy target (mean IoU >= 0.97 at 64³) on a few real default objects."""
    from graspaug.geometry.prepare import SurfaceSettings, prepare_shape

    scores = []
    for _, loaded in default_loaded:
        prepared = prepare_shape(loaded, SurfaceSettings())
        parts = [p.scaled(prepared.normalization.scale, prepared.normalization.offset) for p in loaded.parts]
        grid = fit_grid(prepared.mesh.bounds, 64)
        ours = voxelize_solid(prepared.mesh.vertices, prepared.mesh.faces, grid)
        ref = union_contains(parts, grid.centers().reshape(-1, 3)).reshape(ours.shape)
        scores.append(iou(ours, ref))
    assert np.mean(scores) >= 0.97, scores
