"""Truncated signed distance grids of closed meshes, and their surfaces back by marching cubes."""

import numpy as np
import pytest
import trimesh

from graspaug.geometry.closing import band_distance
from graspaug.geometry.sdf import mesh_from_sdf, surface_samples, truncated_distance_grid
from graspaug.geometry.voxelize import VoxelGrid, fit_grid, voxelize_solid

R = 32
TRUNCATION = 3.0


def box_distance(points: np.ndarray, half: np.ndarray) -> np.ndarray:
    """Unsigned distance (m) from points (n, 3) to the surface of the box [-half, half]."""
    q = np.abs(points) - half
    outside = np.linalg.norm(np.maximum(q, 0), axis=1)
    inside = np.minimum(q.max(axis=1), 0)
    return np.abs(outside + inside)


def cylinder_distance(points: np.ndarray, radius: float, half_height: float) -> np.ndarray:
    """Unsigned distance (m) from points (n, 3) to the surface of the z-axis cylinder."""
    q = np.stack([np.hypot(points[:, 0], points[:, 1]) - radius, np.abs(points[:, 2]) - half_height], axis=1)
    return np.abs(np.linalg.norm(np.maximum(q, 0), axis=1) + np.minimum(q.max(axis=1), 0))


BOX_HALF = np.array([0.031, 0.0215, 0.0137])  # faces between voxel centres, not on them
CYLINDER = (0.02, 0.025)  # radius, half height (m)
SLAB_HALF = np.array([0.04, 0.035, 0.004])  # a thin wide box: two near-planes two voxels apart

SHAPES = {
    "box": (trimesh.creation.box(extents=2 * BOX_HALF), lambda p: box_distance(p, BOX_HALF)),
    "cylinder": (
        trimesh.creation.cylinder(radius=CYLINDER[0], height=2 * CYLINDER[1], sections=128),
        lambda p: cylinder_distance(p, *CYLINDER),
    ),
    "slab": (trimesh.creation.box(extents=2 * SLAB_HALF), lambda p: box_distance(p, SLAB_HALF)),
}


def round_trip(mesh: trimesh.Trimesh, resolution: int = R):
    grid = fit_grid(mesh.bounds, resolution, margin=1)
    sdf = truncated_distance_grid(mesh.vertices, mesh.faces, grid, truncation_voxels=TRUNCATION)
    return grid, sdf, mesh_from_sdf(sdf, grid)


def bumpy_ball() -> trimesh.Trimesh:
    """An ellipsoid with vertex noise: curved, no face on the grid."""
    mesh = trimesh.creation.icosphere(subdivisions=3, radius=0.03)
    mesh.vertices[:, 0] *= 1.4
    mesh.vertices += np.random.default_rng(0).normal(0.0, 0.0008, mesh.vertices.shape)
    return mesh


@pytest.mark.parametrize("resolution", [32, 64])
@pytest.mark.parametrize("name", sorted(SHAPES))
def test_round_trip_lands_on_the_surface(name, resolution):
    mesh, distance = SHAPES[name]
    grid, _, result = round_trip(mesh, resolution)
    assert result.reason is None and result.main_share == 1.0
    assert result.mesh.is_watertight and result.mesh.body_count == 1 and result.mesh.volume > 0
    # the frame voxelize_solid uses: no recentring, every vertex within a quarter voxel of the true surface
    assert distance(result.mesh.vertices).max() < 0.25 * grid.pitch
    # marching cubes cuts the corner of a cell that an edge runs through: a few percent on the 3-voxel slab
    assert result.mesh.volume == pytest.approx(mesh.volume, rel=0.05)


def test_box_faces_come_back_flat():
    mesh, _ = SHAPES["box"]
    grid, _, result = round_trip(mesh)
    centres = result.mesh.triangles_center
    # a point on a face: its distance to the face's nearest edge is the second smallest of (half - |p|); a cell
    # nearer than 1.5 voxels to an edge has inside corners nearer to the other face, which bends its triangles
    to_edge = np.sort(BOX_HALF - np.abs(centres), axis=1)[:, 1]
    flat = to_edge > 1.5 * grid.pitch
    assert flat.sum() > 0.5 * len(centres)
    normals = result.mesh.face_normals[flat]
    off_axis = np.degrees(np.arccos(np.clip(np.abs(normals).max(axis=1), -1, 1)))
    assert off_axis.max() < 2.0


@pytest.mark.parametrize(
    "mesh",
    [
        SHAPES["box"][0],
        SHAPES["cylinder"][0],
        trimesh.creation.torus(major_radius=0.03, minor_radius=0.008),
        trimesh.creation.box(extents=(0.05, 0.03, 0.02), transform=trimesh.transformations.euler_matrix(0.3, 0.7, 1.1)),
        bumpy_ball(),
    ],
    ids=["box", "cylinder", "torus", "turned box", "bumpy ball"],
)
def test_sign_is_the_occupancy(mesh):
    grid = fit_grid(mesh.bounds, R, margin=1)
    sdf = truncated_distance_grid(mesh.vertices, mesh.faces, grid)
    np.testing.assert_array_equal(sdf < 0, voxelize_solid(mesh.vertices, mesh.faces, grid))
    assert (sdf != 0).all()


@pytest.mark.parametrize("resolution", [32, 64])
def test_magnitude_is_the_distance_to_the_nearest_triangle_clamped(resolution):
    mesh = bumpy_ball()
    grid = fit_grid(mesh.bounds, resolution, margin=1)
    sdf = truncated_distance_grid(mesh.vertices, mesh.faces, grid, truncation_voxels=TRUNCATION)
    assert sdf.dtype == np.float32 and sdf.shape == (resolution,) * 3
    assert np.abs(sdf).max() <= TRUNCATION
    # reference: every (voxel centre, triangle) pair within the band, exact
    exact, _ = band_distance(
        mesh.triangles, grid.origin + 0.5 * grid.pitch, grid.pitch, sdf.shape, TRUNCATION * grid.pitch
    )
    within = np.isfinite(exact)
    assert within.sum() > 1000
    np.testing.assert_allclose(np.abs(sdf[within]), np.maximum(exact[within] / grid.pitch, 1e-4), atol=1e-4)
    np.testing.assert_array_equal(np.abs(sdf[~within]), np.float32(TRUNCATION))


def test_surface_samples_cover_each_triangle():
    triangles = np.array(
        [
            [[0, 0, 0], [1, 0, 0], [0, 1, 0]],
            [[0, 0, 0], [30, 0.5, 0], [30, -0.5, 1]],  # a sliver, like a cylinder's side
            [[0, 0, 0], [10, 0, 0], [5, 0.2, 0]],  # a needle with an obtuse corner
        ],
        dtype=float,
    )
    samples, triangle, cover = surface_samples(triangles, spacing=0.5)
    assert cover <= 1.0 and np.bincount(triangle).tolist()[1] < 500
    w = np.random.default_rng(0).dirichlet(np.ones(3), size=(len(triangles), 200))  # points on each triangle
    points = np.einsum("tnc,tcx->tnx", w, triangles)
    for t in range(len(triangles)):
        own = samples[triangle == t]
        normal = np.cross(triangles[t, 1] - triangles[t, 0], triangles[t, 2] - triangles[t, 0])
        assert np.abs((own - triangles[t, 0]) @ normal).max() < 1e-9  # on the triangle's plane
        nearest = np.linalg.norm(points[t, :, None] - own[None], axis=2).min(axis=1)
        assert nearest.max() <= cover


def ball_field(centres: list[tuple[float, float, float]], radius: float) -> np.ndarray:
    ijk = np.indices((R, R, R)).transpose(1, 2, 3, 0)
    distance = np.min([np.linalg.norm(ijk - np.asarray(c), axis=-1) - radius for c in centres], axis=0)
    return np.clip(distance, -TRUNCATION, TRUNCATION)


def test_degenerate_fields_are_rejected_with_reasons():
    grid = VoxelGrid(R, 0.002, np.zeros(3))
    empty = mesh_from_sdf(np.full((R, R, R), TRUNCATION, dtype=np.float32), grid)
    assert empty.mesh is None and empty.reason == "empty field: no voxel inside"
    assert mesh_from_sdf(ball_field([(16, 16, 16)], 2.0), grid).reason.startswith("tiny:")
    two = mesh_from_sdf(ball_field([(8, 16, 16), (24, 16, 16)], 5.0), grid)
    assert two.reason == "in pieces: the largest of 2 holds 50% of the volume"
    one = mesh_from_sdf(ball_field([(16, 16, 16)], 10.0), grid)
    assert one.reason is None
    # a ball of 10 voxels around voxel centre (16, 16, 16), which sits at 16.5 pitches from the origin
    assert one.mesh.volume == pytest.approx(4 / 3 * np.pi * (10 * grid.pitch) ** 3, rel=0.01)
    np.testing.assert_allclose(one.mesh.center_mass, 16.5 * grid.pitch, atol=1e-3 * grid.pitch)
