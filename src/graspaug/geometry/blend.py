"""Shape interpolation without a network: a weighted mean of two solids' signed distance fields.

The ``blend`` pool's control for the AutoEncoder's latent space. Each parent is placed as its
voxel grid places it (:func:`graspaug.geometry.voxelize.fit_grid`: centered on its bounding box,
its largest extent spanning the grid less the margin), sampled at a finer resolution, and its
signed distance field computed from that solid grid by two Euclidean distance transforms
(positive outside, negative inside, in grid cells). The child is ``{(1 - α) d_a + α d_b < 0}``,
meshed by marching cubes and scaled by the parents' interpolated cell size, as ``generate`` scales
a decoded child by the parents' interpolated voxel pitch. A field made from a solid grid puts the
surface midway between the last cell center inside and the first outside: within half a cell of
the parent's surface (at 96 cells, 1/180 of its largest extent).
"""

from __future__ import annotations

import numpy as np
import trimesh
from scipy.ndimage import distance_transform_edt

from graspaug.geometry.fields import largest_piece, surface_from_field
from graspaug.geometry.voxelize import fit_grid, voxelize_solid


def signed_distance_grid(mesh: trimesh.Trimesh, resolution: int, margin: int) -> tuple[np.ndarray, float]:
    """Signed distance field of a closed mesh on its own fitted grid.

    Parameters
    ----------
    mesh : closed triangle mesh, meters
    resolution : int — cells per side, N
    margin : int — empty cells kept on each side along the largest extent

    Returns
    -------
    field : (N, N, N) float32 — distance from each cell center to the nearest cell center of the
        other side (outside: to the solid, positive; inside: to the outside, negative), cells; the
        surface lies where it changes sign
    pitch : float — the cell size, m
    """
    grid = fit_grid(mesh.bounds, resolution, margin)
    inside = voxelize_solid(mesh.vertices, mesh.faces, grid)
    field = distance_transform_edt(~inside) - distance_transform_edt(inside)
    return field.astype(np.float32), grid.pitch


def blend_solids(
    mesh_a: trimesh.Trimesh, mesh_b: trimesh.Trimesh, alpha: float, resolution: int, margin: int
) -> tuple[trimesh.Trimesh | None, str | None]:
    """The solid between two parents at weight ``alpha`` on ``mesh_b`` (0: ``mesh_a``, 1: ``mesh_b``).

    Parameters
    ----------
    mesh_a, mesh_b : closed triangle meshes, meters
    alpha : float — weight of ``mesh_b``'s field, in [0, 1]
    resolution : int — cells per side of each parent's grid (the ingest surface resolution)
    margin : int — empty cells around each parent along its largest extent

    Returns
    -------
    (mesh, None), the child's closed surface, meters, centered on its center of mass; or
    (None, reason) when the mixed field has no solid or its surface is not one closed piece.
    """
    return blend_fields(
        signed_distance_grid(mesh_a, resolution, margin), signed_distance_grid(mesh_b, resolution, margin), alpha
    )


def blend_fields(
    parent_a: tuple[np.ndarray, float], parent_b: tuple[np.ndarray, float], alpha: float
) -> tuple[trimesh.Trimesh | None, str | None]:
    """:func:`blend_solids` from the parents' :func:`signed_distance_grid` (field, pitch), each
    computed once however many pairs a parent is in."""
    (field_a, pitch_a), (field_b, pitch_b) = parent_a, parent_b
    field = (1 - alpha) * field_a + alpha * field_b
    if not (field < 0).any():
        return None, "empty blend: no cell inside both weighted fields"
    pitch = (1 - alpha) * pitch_a + alpha * pitch_b
    outside = float(max(field.max(), 1.0))
    mesh = surface_from_field(np.pad(field, 1, constant_values=outside), np.zeros(3), pitch)
    mesh, dropped = largest_piece(mesh)
    if not mesh.is_watertight or mesh.volume <= 0:
        return None, "blend surface not a closed volume"
    if dropped > 0.1:
        return None, f"blend in pieces: the largest misses {dropped:.0%} of the volume"
    mesh.apply_translation(-mesh.center_mass)
    return mesh, None
