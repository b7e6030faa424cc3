"""Truncated signed distance fields (TSDF) of closed meshes on voxel grids, and surfaces back from them.

The field a signed-distance decoder learns in place of occupancy: at every voxel centre of a
:class:`~graspaug.geometry.voxelize.VoxelGrid` (the placement :func:`~graspaug.geometry.voxelize.voxelize_solid`
samples), the distance to the mesh's surface **in voxels**, negative inside, positive outside, clamped to
``±truncation`` (a ``tanh`` output scaled by the truncation covers it). Its sign is the occupancy of
:func:`~graspaug.geometry.voxelize.voxelize_solid`, so ``sdf < 0`` and the occupancy grid agree voxel for voxel.

Contoured at 0 by marching cubes (:func:`mesh_from_sdf`), the field gives the surface back with sub-voxel
vertices and no smoothing: a face between two voxel centres comes back where it was (the field is linear
across it) and an edge is cut by at most about 0.2 voxel, where the occupancy recipe
(:func:`graspaug.geometry.from_voxels.mesh_decoded`: threshold, opening, marching cubes at 0.5, Humphrey
smoothing) moves faces by up to half a voxel and rounds edges.

Distances are exact point-triangle distances (:func:`graspaug.geometry.closing.closest_on_triangles`) to
candidate triangles: those of the ``_CANDIDATES`` surface samples nearest to the voxel centre (a k-d tree over
:func:`surface_samples`, at most ``_SAMPLE_SPACING`` voxels apart on each triangle). The candidates hold the
triangle of the nearest sample, within ``d + h`` of the centre (``d`` the true distance, ``h`` the samples'
covering radius), so a value is never below the true distance nor above it by more than ``h``. The reference
is every triangle within reach (:func:`~graspaug.geometry.closing.band_distance`, whose cost grows with the
triangle count): ``tests/geometry/test_sdf.py`` checks the field against it to 1e-4 voxel on a bumpy sphere at
32³ and 64³. Only centres that can lie within the truncation of the surface are computed; the rest are clamped.
``trimesh.proximity.closest_point`` was not used: on objects a few centimetres wide it compares squared distances
in m² against a 1e-8 tolerance and returns a farther triangle for a few percent of points (trimesh 5.2), and it is
several times slower.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import trimesh
from scipy import ndimage
from scipy.spatial import cKDTree

from graspaug.geometry.closing import closest_on_triangles
from graspaug.geometry.fields import largest_piece, surface_from_field
from graspaug.geometry.from_voxels import CleanGrid
from graspaug.geometry.settings import DecodeSettings
from graspaug.geometry.voxelize import VoxelGrid, voxelize_solid

# longest step (voxels) between surface samples on a triangle (:func:`surface_samples`): dense enough that the
# nearest triangle is among the few nearest samples' triangles
_SAMPLE_SPACING = 0.5
# nearest surface samples whose triangles are candidates for a voxel centre's nearest triangle
_CANDIDATES = 12
# magnitude (voxels) given to a voxel centre lying on the surface, so that its sign still carries the occupancy
_ON_SURFACE = 1e-4
# (voxel centre, candidate triangle) pairs evaluated at once: about 250 MB of temporaries
_PAIRS_PER_CHUNK = 1_000_000


def truncated_distance_grid(
    vertices: np.ndarray, faces: np.ndarray, grid: VoxelGrid, truncation_voxels: float = 3.0
) -> np.ndarray:
    """Truncated signed distance from each voxel centre of ``grid`` to a closed mesh's surface.

    Parameters
    ----------
    vertices : (n, 3) float — mesh vertices, meters, object frame
    faces : (m, 3) int — triangles of a closed surface (or several), any consistent winding
    grid : VoxelGrid — where to sample (e.g. :func:`~graspaug.geometry.voxelize.fit_grid` of the mesh's bounds)
    truncation_voxels : float — largest magnitude kept, voxels; farther centres get ``±truncation_voxels``

    Returns
    -------
    (R, R, R) float32 — signed distance, voxels (multiply by ``grid.pitch`` for meters): negative where
        :func:`~graspaug.geometry.voxelize.voxelize_solid` says occupied, positive elsewhere, magnitude the
        distance to the nearest surface point clamped to ``truncation_voxels`` (at least ``1e-4`` on the surface)
    """
    if not truncation_voxels > 0:
        raise ValueError(f"truncation_voxels must be positive, got {truncation_voxels}")
    vertices = np.asarray(vertices, dtype=float)
    faces = np.asarray(faces, dtype=np.int64)
    inside = voxelize_solid(vertices, faces, grid)
    R = grid.resolution
    # grid units: voxel centre (i, j, k) sits at (i, j, k)
    v = (vertices - grid.origin) / grid.pitch - 0.5
    triangles = v[faces]  # (m, 3, 3)
    distance = np.full((R, R, R), float(truncation_voxels))
    samples, on_triangle, cover = surface_samples(triangles, _SAMPLE_SPACING)
    if len(samples):
        # centres that can lie within truncation + h of a sample: within truncation + h + √3/2 of a voxel holding one
        holds_sample = np.zeros((R, R, R), dtype=bool)
        holds_sample[tuple(np.clip(np.rint(samples), 0, R - 1).astype(np.int64).T)] = True
        reach = truncation_voxels + cover + np.sqrt(3) / 2
        band = np.argwhere(ndimage.distance_transform_edt(~holds_sample) <= reach)  # (b, 3) voxel indices
        tree = cKDTree(samples)
        for rows in np.array_split(band, max(1, -(-len(band) * _CANDIDATES // _PAIRS_PER_CHUNK))):
            nearest = _nearest_distance(rows.astype(float), tree, on_triangle, triangles, truncation_voxels + cover)
            distance[tuple(rows.T)] = np.minimum(nearest, truncation_voxels)
    distance = np.maximum(distance, _ON_SURFACE)
    return np.where(inside, -distance, distance).astype(np.float32)


def _nearest_distance(
    points: np.ndarray, tree: cKDTree, on_triangle: np.ndarray, triangles: np.ndarray, bound: float
) -> np.ndarray:
    """(b,) distance from points (b, 3) to the nearest of the candidate triangles of each (those of its
    ``_CANDIDATES`` nearest samples in ``tree``, the samples on ``on_triangle``); inf without a sample within
    ``bound``. All in the same unit."""
    near, nearest = tree.query(points, k=_CANDIDATES, distance_upper_bound=bound)  # (b, k); missing: inf
    found = np.isfinite(near)
    point = np.repeat(np.arange(len(points)), found.sum(axis=1))  # (pairs,) the point of each candidate pair
    corners = triangles[on_triangle[nearest[found]]]  # (pairs, 3 corners, 3)
    squared, _ = closest_on_triangles(
        *([corners[:, c, i] for i in range(3)] for c in range(3)), [points[point, i] for i in range(3)]
    )
    best = np.full(len(points), np.inf)
    np.minimum.at(best, point, squared)
    return np.sqrt(best)


def surface_samples(triangles: np.ndarray, spacing: float) -> tuple[np.ndarray, np.ndarray, float]:
    """Points on triangles, every point of each triangle near one of its own samples.

    Each triangle gets a grid in barycentric coordinates from the corner where its longest and shortest edges
    meet: ``n₁ = ⌈longest / spacing⌉`` steps along the longest edge, ``n₂ = ⌈shortest / spacing⌉`` along the
    shortest, the nodes with ``i / n₁ + j / n₂ ≤ 1`` kept (corners included). A sliver gets samples along its
    length only, where ``trimesh.remesh.subdivide_to_size`` would split all three edges (a 64-sided
    cylinder's side, 30 voxels long: 4096 sub-triangles each, a second at 32³ for the cylinder).

    Parameters
    ----------
    triangles : (m, 3, 3) float — corners, any unit
    spacing : float — longest grid step, same unit

    Returns
    -------
    samples : (s, 3) float — points on the triangles
    triangle : (s,) int — the triangle each sample lies on
    cover : float — covering radius: every point of a triangle lies within this of one of its samples
        (at most ``2 * spacing``)
    """
    triangles = np.asarray(triangles, dtype=float)
    m = len(triangles)
    rows = np.arange(m)
    lengths = np.linalg.norm(triangles[:, [1, 2, 0]] - triangles, axis=2)  # (m, 3): edge k joins corners k, k+1
    corner = (np.argsort(lengths, axis=1)[:, 1] + 2) % 3  # opposite the middle edge: longest and shortest meet
    o = triangles[rows, corner]
    p, q = triangles[rows, (corner + 1) % 3], triangles[rows, (corner + 2) % 3]
    lp, lq = np.linalg.norm(p - o, axis=1), np.linalg.norm(q - o, axis=1)
    along_long = np.where((lp >= lq)[:, None], p - o, q - o)  # (m, 3)
    along_short = np.where((lp >= lq)[:, None], q - o, p - o)
    n1 = np.maximum(np.ceil(np.maximum(lp, lq) / spacing), 1).astype(np.int64)
    n2 = np.maximum(np.ceil(np.minimum(lp, lq) / spacing), 1).astype(np.int64)
    cover = float(np.max(np.maximum(lp, lq) / n1 + np.minimum(lp, lq) / n2)) if m else 0.0
    # every node (i, j) of each triangle's (n₁ + 1) x (n₂ + 1) rectangle, then those inside
    count = (n1 + 1) * (n2 + 1)
    t = np.repeat(rows, count)
    local = np.arange(count.sum()) - np.repeat(np.cumsum(count) - count, count)
    i, j = local // (n2[t] + 1), local % (n2[t] + 1)
    keep = i * n2[t] + j * n1[t] <= n1[t] * n2[t]
    t, i, j = t[keep], i[keep], j[keep]
    samples = o[t] + (i / n1[t])[:, None] * along_long[t] + (j / n2[t])[:, None] * along_short[t]
    return samples, t, cover


@dataclass(frozen=True)
class FieldSurface:
    """A closed surface contoured from a signed distance grid, or why there is none (``reason`` not None).

    Attributes
    ----------
    mesh : closed, outward-oriented surface of the largest piece, meters, the grid's frame; None when rejected
        for an empty field
    main_share : float — the largest piece's share of the enclosed volume (1 for one piece)
    reason : str or None — why the field was rejected, in words (``empty field``, ``tiny: …``, ``in pieces: …``,
        ``surface not a closed volume …``)
    """

    mesh: trimesh.Trimesh | None
    main_share: float
    reason: str | None


def mesh_from_sdf(
    sdf: np.ndarray,
    grid: VoxelGrid,
    level: float = 0.0,
    min_volume_voxels: float = 100.0,
    min_main_share: float = 0.9,
) -> FieldSurface:
    """The surface ``{sdf = level}`` of a signed distance grid, by marching cubes, in meters.

    Marching cubes (Lewiner) on the grid padded with one layer of outside values, so the surface closes;
    vertices stay where the field crosses ``level`` between voxel centres (no opening, no smoothing). The
    largest connected piece is kept. The rejections mirror :func:`graspaug.geometry.from_voxels.clean_occupancy`
    (defaults: its ``min_voxels`` and ``min_main_share`` of :class:`~graspaug.geometry.settings.DecodeSettings`).

    Parameters
    ----------
    sdf : (R, R, R) float — signed distance at the voxel centres, voxels, negative inside
        (:func:`truncated_distance_grid`, or a decoder's output)
    grid : VoxelGrid — where the centres lie: voxel ``(i, j, k)``'s centre is ``origin + pitch * (ijk + 0.5)``
        meters (for a decode without an origin, ``VoxelGrid(R, pitch, np.zeros(3))``)
    level : float — the contour, voxels
    min_volume_voxels : float — a largest piece enclosing fewer voxels³ is rejected (tiny)
    min_main_share : float — a surface whose largest piece encloses less than this share of the volume is
        rejected (in pieces)

    Returns
    -------
    FieldSurface — the mesh in the frame ``voxelize_solid`` uses (a round trip lands on the original mesh),
        or a reason
    """
    sdf = np.asarray(sdf, dtype=float)
    R = grid.resolution
    if sdf.shape != (R, R, R):
        raise ValueError(f"sdf must have the grid's shape {(R, R, R)}, got {sdf.shape}")
    if not (sdf < level).any():
        return FieldSurface(None, 0.0, "empty field: no voxel inside")
    outside = max(float(sdf.max()), level + 1.0)
    # padded sample (0, 0, 0) is voxel (-1, -1, -1), centred at origin - pitch / 2; the field goes to meters
    # so that surface_from_field's tie-breaking offset of the level is in the same unit
    surface = surface_from_field(
        np.pad(sdf, 1, constant_values=outside) * grid.pitch,
        grid.origin - 0.5 * grid.pitch,
        grid.pitch,
        level * grid.pitch,
    )
    if surface.is_empty:
        return FieldSurface(None, 0.0, "empty field: no surface at the level")
    pieces = surface.body_count
    mesh, dropped = largest_piece(surface)
    share = 1.0 - dropped
    if not mesh.is_volume:
        return FieldSurface(mesh, share, "surface not a closed volume after meshing")
    volume = mesh.volume / grid.pitch**3
    if volume < min_volume_voxels:
        return FieldSurface(mesh, share, f"tiny: {volume:.0f} voxels³ < {min_volume_voxels:g}")
    if share < min_main_share:
        return FieldSurface(mesh, share, f"in pieces: the largest of {pieces} holds {share:.0%} of the volume")
    return FieldSurface(mesh, share, None)


def mesh_decoded_field(
    field: np.ndarray, pitch: float, truncation: float, settings: DecodeSettings
) -> tuple[CleanGrid, trimesh.Trimesh | None, str | None]:
    """A decoded signed distance grid as :func:`graspaug.geometry.from_voxels.mesh_decoded` gives a decoded occupancy
    grid: its inside (``field < 0``) with the largest piece's share, and the surface at 0 (:func:`mesh_from_sdf`,
    ``settings``' ``min_voxels`` and ``min_main_share``; no opening, no smoothing), ``pitch`` m per voxel, centred on
    its center of mass; or a reason instead of a mesh.

    Parameters
    ----------
    field : (R, R, R) float — signed distance / ``truncation`` (a decode, in [-1, 1]), negative inside
    pitch : float — voxel edge, m
    truncation : float — voxels
    settings : DecodeSettings
    """
    r = field.shape[0]
    surface = mesh_from_sdf(
        np.asarray(field, dtype=np.float32) * truncation,
        VoxelGrid(r, pitch, np.zeros(3)),
        min_volume_voxels=settings.min_voxels,
        min_main_share=settings.min_main_share,
    )
    grid = CleanGrid(np.asarray(field) < 0, surface.main_share, surface.reason)
    if surface.reason:
        return grid, None, surface.reason
    mesh = surface.mesh
    mesh.apply_translation(-mesh.center_mass)
    return grid, mesh, None
