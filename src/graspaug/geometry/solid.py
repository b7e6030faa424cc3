"""Solids made of convex parts, and one closed outer surface for them.

The default corpus (pybullet's ``random_urdfs``) stores every object as an
assembly of convex parts that touch face to face. Ray casting and parity tests
on such an assembly see the coincident inner faces, so every later stage works
on one closed outer surface rebuilt here:

1. each convex part is its set of half-spaces ``n·x + d <= 0`` (qhull),
2. the union's piecewise-linear field ``f(x) = min_part max_plane (n·x + d)`` is
   negative inside, positive outside and exactly zero on the union's boundary
   (its value is the distance to the nearest face plane, so it is linear across
   every flat face),
3. marching cubes (Lewiner) on ``f`` sampled on a fine grid gives a closed
   surface whose vertices lie on the true boundary wherever a cell edge does not
   straddle a crease; flat faces stay flat, sharp edges are cut by at most one
   fine cell,
4. the largest connected piece is kept and decimated to a face budget.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import trimesh
from scipy.spatial import ConvexHull, QhullError

from graspaug.geometry.fields import decimate, grid_around, largest_piece, surface_from_field


@dataclass(frozen=True)
class ConvexPart:
    """One convex part as half-spaces.

    Attributes
    ----------
    normals : (p, 3) float — unit outward face normals
    offsets : (p,) float — plane offsets d, meters: inside iff ``normals @ x + d <= 0``
    bounds : (2, 3) float — axis-aligned bounds of the part, meters
    """

    normals: np.ndarray
    offsets: np.ndarray
    bounds: np.ndarray

    def field(self, points: np.ndarray) -> np.ndarray:
        """(n,) float — ``max_plane (n·x + d)`` at (n, 3) ``points``; <= 0 inside, meters."""
        return (points @ self.normals.T + self.offsets).max(axis=1)

    def scaled(self, scale: float, offset: np.ndarray) -> "ConvexPart":
        """The part after ``x -> scale * x + offset`` (uniform scale > 0, then translation)."""
        offset = np.asarray(offset, dtype=float)
        return ConvexPart(self.normals, scale * self.offsets - self.normals @ offset, scale * self.bounds + offset)


def convex_part(vertices: np.ndarray) -> ConvexPart | None:
    """Half-space form of the convex hull of (n, 3) ``vertices``; None if it has no volume."""
    vertices = np.asarray(vertices, dtype=float)
    if len(vertices) < 4 or not np.isfinite(vertices).all():
        return None
    try:
        hull = ConvexHull(vertices)
    except QhullError:
        return None
    if not hull.volume > 0:
        return None
    eq = hull.equations
    return ConvexPart(eq[:, :3].copy(), eq[:, 3].copy(), np.array([vertices.min(0), vertices.max(0)]))


def union_contains(parts: list[ConvexPart], points: np.ndarray, tol: float = 0.0) -> np.ndarray:
    """(n,) bool — which (n, 3) ``points`` lie inside any part (half-space tests, exact)."""
    points = np.asarray(points, dtype=float)
    inside = np.zeros(len(points), dtype=bool)
    for part in parts:
        box = np.all((points >= part.bounds[0] - tol) & (points <= part.bounds[1] + tol), axis=1)
        idx = np.flatnonzero(box & ~inside)
        if len(idx):
            inside[idx] = part.field(points[idx]) <= tol
    return inside


def resolution_for_parts(parts: list[ConvexPart], base: int, finest: int, cells_per_thickness: float) -> int:
    """Field samples along the largest extent so that a typical part is ``cells_per_thickness`` cells thick.

    A part's thickness is taken as the smallest extent of its bounding box; the
    median over parts is used. Lattices of thin parts get a finer grid (up to
    ``finest``); ordinary shapes stay at ``base``.
    """
    extents = np.array([p.bounds[1] - p.bounds[0] for p in parts])
    size = float(np.max(np.max([p.bounds[1] for p in parts], axis=0) - np.min([p.bounds[0] for p in parts], axis=0)))
    thickness = float(np.median(extents.min(axis=1)))
    if not thickness > 0:
        return finest
    return int(np.clip(np.ceil(cells_per_thickness * size / thickness), base, max(base, finest)))


def union_field_grid(
    parts: list[ConvexPart], origin: np.ndarray, pitch: float, shape: tuple[int, int, int]
) -> np.ndarray:
    """The union's field sampled on a regular grid, ``min_part max_plane (n·x + d)``.

    Exact within ``2 * pitch`` of some part's bounding box; samples farther away get
    ``2 * pitch`` (they are outside, and marching cubes only needs exact values at
    the corners of cells that the surface crosses).

    Parameters
    ----------
    origin : (3,) float — position of sample (0, 0, 0), meters
    pitch : float — sample spacing, meters
    shape : (3,) int — samples per axis

    Returns
    -------
    (a, b, c) float — field values, meters
    """
    reach = 2 * pitch
    field = np.full(shape, reach)
    axes = [origin[i] + pitch * np.arange(shape[i]) for i in range(3)]
    for part in parts:
        lo = np.maximum(np.floor((part.bounds[0] - reach - origin) / pitch).astype(int), 0)
        hi = np.minimum(np.ceil((part.bounds[1] + reach - origin) / pitch).astype(int) + 1, shape)
        x, y, z = (axes[i][lo[i] : hi[i]] for i in range(3))
        box = np.full((len(x), len(y), len(z)), -np.inf)
        for (nx, ny, nz), d in zip(part.normals, part.offsets):
            plane = (nx * x + d)[:, None, None] + (ny * y)[None, :, None] + (nz * z)[None, None, :]
            np.maximum(box, plane, out=box)
        view = field[lo[0] : hi[0], lo[1] : hi[1], lo[2] : hi[2]]
        np.minimum(view, box, out=view)
    return field


def outer_surface_of_parts(parts: list[ConvexPart], resolution: int, face_budget: int) -> tuple[trimesh.Trimesh, float]:
    """One closed outer surface of the union of convex ``parts``.

    Parts that almost touch (gaps under about two field cells, as between some
    pieces of the default corpus) would come out as separate pieces; when the
    first surface has several, the solid is closed morphologically (grey-scale
    opening of the field with a 3-cell cube: exact on flat faces, fills only gaps
    and concave creases narrower than that) and the surface rebuilt.

    Parameters
    ----------
    parts : convex parts, meters
    resolution : int — field samples along the largest extent (cell = extent / resolution)
    face_budget : int — maximum faces after decimation

    Returns
    -------
    mesh : closed, outward-oriented surface of the largest connected piece, meters
    dropped : float — share of the union's volume in pieces that were dropped
    """
    from scipy import ndimage

    bounds = np.array([np.min([p.bounds[0] for p in parts], axis=0), np.max([p.bounds[1] for p in parts], axis=0)])
    origin, pitch, shape = grid_around(bounds, resolution, pad_cells=2)
    field = union_field_grid(parts, origin, pitch, shape)
    mesh, dropped = largest_piece(surface_from_field(field, origin, pitch))
    if dropped > 0:
        closed = ndimage.grey_opening(field, size=(3, 3, 3))  # min then max filter: closes the solid
        mesh, dropped = largest_piece(surface_from_field(closed, origin, pitch))
    return decimate(mesh, face_budget), dropped
