"""Solid (interior-filled) voxelization of closed triangle meshes.

The grid convention used across the project: voxel ``(i, j, k)`` covers the cube
``origin + pitch * [i, i+1) x [j, j+1) x [k, k+1)`` and is occupied when its
*center* ``origin + pitch * (ijk + 0.5)`` lies inside the solid.

Inside/outside is decided per grid column along z by the signed crossing count
(the winding number of the surface around a vertical ray): every triangle that a
column's vertical line pierces adds ``-sign(n_z)`` to all voxel centers above
the piercing point. For a closed, consistently oriented surface the running sum
is 1 inside and 0 outside; for several overlapping closed bodies it counts how
many contain the point, so ``!= 0`` is their union. Only the column/triangle
pairs whose 2-D bounding boxes overlap are visited, so the cost scales with the
surface, not the volume.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

# Columns are shifted by this fraction of a voxel so that a vertical line through
# a voxel center never passes exactly through a mesh edge or vertex in practice
# (the grid is fit to the mesh bounds, which would otherwise put vertices on it).
_COLUMN_JITTER = np.array([1.3e-6, 2.9e-6])


@dataclass(frozen=True)
class VoxelGrid:
    """Placement of an ``R x R x R`` grid in the object frame.

    Attributes
    ----------
    resolution : int — voxels per side, R
    pitch : float — edge length of one voxel, meters
    origin : (3,) float — object-frame position of the grid's corner, meters
    """

    resolution: int
    pitch: float
    origin: np.ndarray

    def centers(self) -> np.ndarray:
        """(R, R, R, 3) float — voxel centers in the object frame, meters."""
        idx = (np.arange(self.resolution) + 0.5) * self.pitch
        grid = np.stack(np.meshgrid(idx, idx, idx, indexing="ij"), axis=-1)
        return grid + self.origin


def fit_grid(bounds: np.ndarray, resolution: int, margin: int = 1) -> VoxelGrid:
    """Grid of ``resolution``³ voxels that holds ``bounds`` with ``margin`` empty voxels.

    The object is scaled uniformly: its largest extent spans ``resolution - 2*margin``
    voxels and it is centered in the grid.

    Parameters
    ----------
    bounds : (2, 3) float — axis-aligned bounds of the object, meters
    resolution : int — voxels per side
    margin : int — empty voxels kept on each side along the largest extent
    """
    bounds = np.asarray(bounds, dtype=float)
    if resolution <= 2 * margin:
        raise ValueError(f"resolution {resolution} leaves no room inside a margin of {margin}")
    extent = float(np.max(bounds[1] - bounds[0]))
    if not extent > 0:
        raise ValueError("bounds have zero extent")
    pitch = extent / (resolution - 2 * margin)
    center = bounds.mean(axis=0)
    return VoxelGrid(resolution, pitch, center - 0.5 * resolution * pitch)


def voxelize_solid(vertices: np.ndarray, faces: np.ndarray, grid: VoxelGrid) -> np.ndarray:
    """Solid occupancy of a closed triangle mesh at the voxel centers of ``grid``.

    Parameters
    ----------
    vertices : (n, 3) float — mesh vertices, meters, object frame
    faces : (m, 3) int — triangles; a closed surface (or several), any consistent winding
    grid : VoxelGrid — where to sample

    Returns
    -------
    (R, R, R) bool — True where the voxel center is inside the solid
    """
    R = grid.resolution
    # grid units: voxel center (i, j, k) sits at (i + 0.5, j + 0.5, k + 0.5)
    v = (np.asarray(vertices, dtype=float) - grid.origin) / grid.pitch
    tri = v[np.asarray(faces)]  # (m, 3 corners, 3 xyz)
    a, b, c = tri[:, 0], tri[:, 1], tri[:, 2]
    # signed double area of the xy projection; its sign is the sign of n_z
    area2 = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])
    keep = np.abs(area2) > 1e-12
    tri, area2 = tri[keep], area2[keep]

    # column index range covered by each triangle's xy bounding box
    off = 0.5 + _COLUMN_JITTER  # column line x = i + off[0], y = j + off[1]
    lo = np.ceil(tri[:, :, :2].min(axis=1) - off).astype(np.int64)
    hi = np.floor(tri[:, :, :2].max(axis=1) - off).astype(np.int64)
    lo = np.clip(lo, 0, R - 1)
    hi = np.clip(hi, -1, R - 1)
    nx = np.maximum(hi[:, 0] - lo[:, 0] + 1, 0)
    ny = np.maximum(hi[:, 1] - lo[:, 1] + 1, 0)
    count = nx * ny
    if count.sum() == 0:
        return np.zeros((R, R, R), dtype=bool)

    # expand to (triangle, column) candidate pairs
    t = np.repeat(np.arange(len(tri)), count)
    start = np.cumsum(count) - count
    local = np.arange(count.sum()) - np.repeat(start, count)
    ci = lo[t, 0] + local // ny[t]
    cj = lo[t, 1] + local % ny[t]
    px = ci + off[0]
    py = cj + off[1]

    ta, tb, tc = tri[t, 0], tri[t, 1], tri[t, 2]
    # barycentric weights of the column point in the projected triangle
    wa = ((tb[:, 0] - px) * (tc[:, 1] - py) - (tb[:, 1] - py) * (tc[:, 0] - px)) / area2[t]
    wb = ((tc[:, 0] - px) * (ta[:, 1] - py) - (tc[:, 1] - py) * (ta[:, 0] - px)) / area2[t]
    wc = 1.0 - wa - wb
    hit = (wa >= 0) & (wb >= 0) & (wc >= 0)
    t, ci, cj = t[hit], ci[hit], cj[hit]
    z = wa[hit] * ta[hit, 2] + wb[hit] * tb[hit, 2] + wc[hit] * tc[hit, 2]
    # entering the solid going up (+z) means the outward normal points down
    step = -np.sign(area2[t]).astype(np.int32)

    # a crossing at height z affects the voxel centers k + 0.5 > z
    k0 = np.clip(np.ceil(z - 0.5).astype(np.int64), 0, R)
    acc = np.zeros((R, R, R + 1), dtype=np.int32)
    np.add.at(acc, (ci, cj, k0), step)
    winding = np.cumsum(acc[:, :, :R], axis=2)
    # outward winding counts +1 per enclosing body, inward winding -1: either way
    # a nonzero count is inside
    return winding != 0


def pack_bits(occupancy: np.ndarray) -> np.ndarray:
    """(N, R, R, R) bool → (N, R³/8) uint8, C order, big-endian bits (numpy packbits)."""
    occupancy = np.asarray(occupancy, dtype=bool)
    return np.packbits(occupancy.reshape(len(occupancy), -1), axis=1)


def unpack_bits(packed: np.ndarray, resolution: int) -> np.ndarray:
    """Inverse of :func:`pack_bits`: (N, R³/8) uint8 → (N, R, R, R) bool."""
    n = len(packed)
    flat = np.unpackbits(packed, axis=1, count=resolution**3)
    return flat.reshape(n, resolution, resolution, resolution).astype(bool)


def iou(a: np.ndarray, b: np.ndarray) -> float:
    """Intersection over union of two boolean arrays (1.0 when both are empty)."""
    a = np.asarray(a, dtype=bool)
    b = np.asarray(b, dtype=bool)
    union = np.logical_or(a, b).sum()
    if union == 0:
        return 1.0
    return float(np.logical_and(a, b).sum() / union)
