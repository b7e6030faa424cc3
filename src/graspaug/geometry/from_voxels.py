"""Decoded occupancy grids → closed surface meshes in meters (paper Section III-C).

Threshold, fill holes, binary opening, keep the largest face-connected piece, marching cubes
(Lewiner), Humphrey smoothing (Vollmer et al. 1999).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import trimesh
from scipy import ndimage
from skimage.measure import marching_cubes

from graspaug.geometry.settings import DecodeSettings


@dataclass(frozen=True)
class CleanGrid:
    """A cleaned occupancy grid (R, R, R) bool, or why it was rejected (``reason`` not None).

    ``main_share`` is the largest piece's share of the voxels after opening (1 for one piece)."""

    occupancy: np.ndarray
    main_share: float
    reason: str | None


def clean_occupancy(
    probability: np.ndarray, threshold: float, opening: int, min_voxels: int, min_main_share: float
) -> CleanGrid:
    """Binary solid from decoded probabilities (R, R, R): ``> threshold``, holes filled, opened
    ``opening`` times (removes one-voxel spurs), reduced to its largest face-connected piece
    (voxels touching only along an edge or corner would make separate surfaces).

    Rejected (``reason`` set) when nothing is left, fewer than ``min_voxels`` voxels are, or
    the largest piece holds less than ``min_main_share`` of them (a shape in many pieces)."""
    solid = ndimage.binary_fill_holes(probability > threshold)
    if opening > 0:
        solid = ndimage.binary_opening(solid, structure=ndimage.generate_binary_structure(3, 1), iterations=opening)
    total = int(solid.sum())
    if total == 0:
        return CleanGrid(solid, 0.0, "empty decode")
    labels, n = ndimage.label(solid, structure=ndimage.generate_binary_structure(3, 1))
    sizes = np.bincount(labels.ravel())[1:]
    main = labels == (1 + int(np.argmax(sizes)))
    share = float(sizes.max() / total)
    if sizes.max() < min_voxels:
        return CleanGrid(main, share, f"tiny: {int(sizes.max())} voxels < {min_voxels}")
    if share < min_main_share:
        return CleanGrid(main, share, f"in pieces: the largest of {n} holds {share:.0%} of the voxels")
    return CleanGrid(main, share, None)


def mesh_from_occupancy(occupancy: np.ndarray, pitch: float, smoothing_iterations: int) -> trimesh.Trimesh:
    """Closed triangle mesh (meters) of a solid grid (R, R, R) bool with voxels ``pitch`` m wide,
    its center of mass at the origin: marching cubes at level 0.5 on the zero-padded grid, then
    ``smoothing_iterations`` of Humphrey smoothing. A face-connected grid gives one piece."""
    padded = np.pad(occupancy.astype(np.float32), 1)
    vertices, faces, _, _ = marching_cubes(padded, level=0.5, method="lewiner")
    mesh = trimesh.Trimesh(vertices * pitch, faces[:, ::-1], process=True)  # skimage winds inward here
    if smoothing_iterations > 0:
        trimesh.smoothing.filter_humphrey(mesh, iterations=smoothing_iterations)
    if mesh.is_watertight and mesh.volume < 0:
        mesh.invert()
    center = mesh.center_mass if mesh.is_watertight else mesh.bounds.mean(axis=0)
    mesh.apply_translation(-center)
    return mesh


def mesh_decoded(
    probability: np.ndarray, pitch: float, settings: DecodeSettings
) -> tuple[CleanGrid, trimesh.Trimesh | None, str | None]:
    """Clean a decoded grid (R, R, R) of probabilities and mesh it at ``pitch`` (m per voxel);
    a reason instead of a mesh when it is degenerate."""
    grid = clean_occupancy(
        probability, settings.threshold, settings.opening, settings.min_voxels, settings.min_main_share
    )
    if grid.reason:
        return grid, None, grid.reason
    mesh = mesh_from_occupancy(grid.occupancy, pitch, settings.smoothing_iterations)
    pieces = len(mesh.split(only_watertight=False))
    if pieces != 1:
        return grid, None, f"surface in {pieces} pieces after meshing"
    if not mesh.is_volume:
        return grid, None, "surface not a closed volume after meshing"
    return grid, mesh, None
