"""Solids from open meshes: scans with holes, textured exports split at seams, stray pieces.

A lab's own scans are rarely closed: textured OBJ files split vertices at UV seams
(merged by position in :func:`graspaug.geometry.loading.load_shape`), scanners leave
small holes and hair cracks between pieces, and some pieces float inside the object.
:func:`close_surface` keeps a closed mesh as it is and rebuilds an open one by
:func:`fill_open_mesh`, which decides inside from outside on a field grid (cell =
largest extent / resolution):

1. exact distance ``d`` from every grid sample within one cell of the triangles
   (point-triangle distances on candidate pairs; the triangles are subdivided to at
   most four cells first so that candidate boxes stay small),
2. the *shell*: samples with ``d <= sqrt(3)/2`` cells, a layer that no 26-connected
   path of other samples crosses where the surface is closed,
3. *outside*: the samples off the shell farther than ``max_gap / 2`` from the surface
   that a flood fill from the grid border reaches (``scipy.ndimage.label``), grown back
   by that much (a morphological closing with a ball): a hole or crack narrower than
   ``max_gap`` is bridged, a wider opening (a mug's top, a handle's loop) lets the
   outside in, so real cavities stay; concave gaps narrower than ``max_gap`` are
   filled too,
4. the side of each shell sample is read off the first classified sample met walking
   away from the surface along the nearest triangle's normal (an outside sample stays
   outside moving away from the surface, an inside one goes deeper); a walk that heads
   into another surface first is inside a wall thinner than the shell (or in a crack,
   which the closing bridges anyway). No consistent winding is needed; open flaps
   (outside on both sides) and stray inner pieces (inside on both sides) leave no
   surface,
5. the signed field ``±d`` goes through marching cubes, the largest piece is kept and
   decimated, as for the other rebuilt shapes: the surface sits at the exact distance
   zero crossing, not on voxel faces.

The share of the mesh's area that bounds the solid (``enclosed``) tells a scan with a
hole wider than ``max_gap`` (the outside floods in, the walls bound nothing) or an open
sheet from a closed one; below ``MIN_ENCLOSED`` the fill is tried once more at the
finest resolution (walls thinner than about 1.5 cells vanish like flooded ones).

Chosen by measurement on the meshes of ``tests/geometry/scan_meshes.py`` (resolution
96, ``max_gap`` 0.05; volume / true volume, and the distance of the rebuilt surface to
the true one, mean and 95th percentile in cells):

=========================  ==================  ======================  ======================
mesh                       exact ``±d`` field  occupancy of the sides  filled voxel shell
                           (this module)       (step 4, smoothed,      (shell + closing,
                                               contoured at 0.5)       smoothed, at 0.5)
=========================  ==================  ======================  ======================
ball, three 3 mm holes     1.000, 0.01 / 0.03  0.999, 0.08 / 0.20      1.014, 0.26 / 0.61
scan-like can [#]_         0.999, 0.08 / 0.19  0.997, 0.12 / 0.34      0.999, 0.12 / 0.37
mug, 5 mm walls, 4 mm      0.999, 0.01 / 0.02  0.981, 0.18 / 0.50      0.960, 0.20 / 0.50
holes (cavity kept)
mug, 3 mm walls            0.998, 0.01 / 0.02  0.971, 0.18 / 0.50      0.957, 0.20 / 0.50
=========================  ==================  ======================  ======================

.. [#] 10 pieces with hair cracks, 0.15 mm (0.14 cell) vertex noise, two 4 mm holes,
   a stray inner blob and flap, UV seams.

The same meshes with the fill before this module (a sampled shell per open piece,
``binary_fill_holes``): seamed exports crashed in marching cubes, the holed ball came
out a hollow shell (volume 0.07 of the ball's). A generalized winding number was not
tried: no installed library evaluates it fast (brute force is faces x samples), it
needs consistent winding, and open flaps give it +-0.5 on their two sides. Walls: 2 mm
on a 10 cm mug (1.9 cells) keep 0.96 of their volume, 1.5 mm 0.99 (second fill at
160), 1 mm is rejected. Time on 2 shared cores: 1 to 3 s per mesh of 8k to 20k faces.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import trimesh
from scipy import ndimage

from graspaug.geometry.fields import decimate, grid_around, largest_piece, surface_from_field
from graspaug.geometry.voxelize import VoxelGrid, voxelize_solid

# an open mesh whose fill leaves more of its area than 1 - this bounding nothing is not closed
MIN_ENCLOSED = 0.9
# pairs of (sample, triangle) evaluated at once in the distance pass
_PAIRS_PER_CHUNK = 1_000_000  # about 300 MB of temporaries
# the shell: samples this close to the surface, in cells; sqrt(3)/2 makes it leak-proof
# for 26-connected paths (a grid step that crosses the surface has an end this close)
_SHELL = 0.8661
# steps (cells) along which a shell sample looks for a classified sample
_WALK = (0.5, 0.75, 1.0, 1.25, 1.5, 1.75, 2.0, 2.5, 3.0, 3.5)


@dataclass
class FilledSolid:
    """An open mesh rebuilt as a solid.

    Attributes
    ----------
    mesh : closed, outward-oriented surface of the largest piece (empty when nothing is inside), meters
    dropped : share of the solid's volume in pieces that were dropped
    enclosed : share of the source triangles' area that bounds the solid (1: every triangle
        has inside on one side; open flaps and walls the outside floods around count as 0)
    gap_m : the widest gap bridged, meters
    """

    mesh: trimesh.Trimesh
    dropped: float
    enclosed: float
    gap_m: float


@dataclass
class ClosedSurface:
    """One closed outer surface for a mesh, and how it was closed.

    Attributes
    ----------
    mesh : closed, outward-oriented surface, meters
    dropped : share of the solid's volume in pieces that were dropped
    filled : True when rebuilt by :func:`fill_open_mesh` (the mesh was open)
    enclosed : share of the area that bounds the solid (1.0 for a closed mesh)
    gap_m : the widest gap bridged, meters (0.0 for a closed mesh)
    resolution : field samples along the largest extent that were used
    """

    mesh: trimesh.Trimesh
    dropped: float
    filled: bool
    enclosed: float
    gap_m: float
    resolution: int


def _dot(p: list[np.ndarray], q: list[np.ndarray]) -> np.ndarray:
    return p[0] * q[0] + p[1] * q[1] + p[2] * q[2]


def closest_on_triangles(
    a: list[np.ndarray], b: list[np.ndarray], c: list[np.ndarray], x: list[np.ndarray]
) -> tuple[np.ndarray, list[np.ndarray]]:
    """Closest points on triangles ``(a, b, c)`` to points ``x``, pair by pair.

    The projection onto the triangle's plane when it falls inside, else the nearest
    point of its three edges. Every argument is the three coordinate arrays (n,) of n
    points: column arrays keep this about twice as fast as ``trimesh.triangles.closest_point``.

    Returns
    -------
    sq : (n,) float — squared distances
    closest : the three coordinate arrays (n,) of the closest points
    """
    e0 = [b[i] - a[i] for i in range(3)]
    e1 = [c[i] - a[i] for i in range(3)]
    w = [x[i] - a[i] for i in range(3)]
    d00, d01, d11, d20, d21 = _dot(e0, e0), _dot(e0, e1), _dot(e1, e1), _dot(w, e0), _dot(w, e1)
    den = d00 * d11 - d01 * d01
    with np.errstate(divide="ignore", invalid="ignore"):
        u = (d11 * d20 - d01 * d21) / den
        v = (d00 * d21 - d01 * d20) / den
    inner = (u >= 0) & (v >= 0) & (u + v <= 1) & (den > 0)
    best = [a[i] + u * e0[i] + v * e1[i] for i in range(3)]
    r = [x[i] - best[i] for i in range(3)]
    best_sq = np.where(inner, _dot(r, r), np.inf)
    for p, q in ((a, b), (b, c), (c, a)):
        edge = [q[i] - p[i] for i in range(3)]
        with np.errstate(divide="ignore", invalid="ignore"):
            t = np.clip(np.nan_to_num(_dot([x[i] - p[i] for i in range(3)], edge) / _dot(edge, edge)), 0.0, 1.0)
        point = [p[i] + t * edge[i] for i in range(3)]
        r = [x[i] - point[i] for i in range(3)]
        sq = _dot(r, r)
        closer = sq < best_sq
        best_sq = np.where(closer, sq, best_sq)
        best = [np.where(closer, point[i], best[i]) for i in range(3)]
    return best_sq, best


def band_distance(
    triangles: np.ndarray, origin: np.ndarray, pitch: float, shape: tuple[int, int, int], radius: float
) -> tuple[np.ndarray, np.ndarray]:
    """Exact distance to the triangles at the grid samples within ``radius`` of them.

    Every (sample, triangle) pair within the triangle's bounding sphere grown by
    ``radius`` is evaluated, so triangles of a few cells at most keep this fast.

    Parameters
    ----------
    triangles : (m, 3, 3) float — meters
    origin : (3,) float — position of sample (0, 0, 0), meters
    pitch : float — sample spacing, meters
    shape : (3,) int — samples per axis
    radius : float — band half-width, meters

    Returns
    -------
    dist : (a, b, c) float — distance in meters, ``inf`` outside the band
    away : (a, b, c, 3) float32 — unit direction away from the surface at the sample: the
        nearest triangle's normal turned toward the sample (off a crack or a hole's rim too),
        or the direction from the nearest point when the sample lies in that triangle's plane;
        0 on the surface
    """
    n_samples = int(np.prod(shape))
    dist = np.full(n_samples, np.inf)
    away = np.zeros((n_samples, 3), dtype=np.float32)
    dims = np.array(shape)
    center = triangles.mean(axis=1)
    reach = np.linalg.norm(triangles - center[:, None], axis=2).max(axis=1) + radius
    lo = np.clip(np.ceil((center - reach[:, None] - origin) / pitch).astype(np.int64), 0, dims - 1)
    hi = np.clip(np.floor((center + reach[:, None] - origin) / pitch).astype(np.int64), 0, dims - 1)
    box = np.maximum(hi - lo + 1, 0)
    count = box.prod(axis=1)
    ends = np.cumsum(count)
    corner = [[np.ascontiguousarray(triangles[:, k, i]) for i in range(3)] for k in range(3)]
    normal = np.cross(triangles[:, 1] - triangles[:, 0], triangles[:, 2] - triangles[:, 0])
    with np.errstate(divide="ignore", invalid="ignore"):
        normal = np.nan_to_num(normal / np.linalg.norm(normal, axis=1, keepdims=True))
    mid = [np.ascontiguousarray(center[:, i]) for i in range(3)]
    start = 0
    while start < len(triangles):
        # the triangles whose pairs fit in one chunk (at least one triangle)
        base = ends[start - 1] if start else 0
        stop = max(int(np.searchsorted(ends, base + _PAIRS_PER_CHUNK, side="right")), start + 1)
        tri = np.repeat(np.arange(start, stop), count[start:stop])
        local = np.arange(len(tri)) - np.repeat(ends[start:stop] - count[start:stop] - base, count[start:stop])
        by, bz = box[tri, 1], box[tri, 2]
        ijk = [lo[tri, 0] + local // (by * bz), lo[tri, 1] + (local // bz) % by, lo[tri, 2] + local % bz]
        x = [origin[i] + pitch * ijk[i] for i in range(3)]
        rel = [x[i] - mid[i][tri] for i in range(3)]
        within = np.flatnonzero(_dot(rel, rel) <= reach[tri] ** 2)
        tri = tri[within]
        ijk = [ijk[i][within] for i in range(3)]
        x = [x[i][within] for i in range(3)]
        sq, near = closest_on_triangles(*([corner[k][i][tri] for i in range(3)] for k in range(3)), x)
        keep = np.flatnonzero(sq <= radius**2)
        d = np.sqrt(sq[keep])
        flat = np.ravel_multi_index(tuple(ijk[i][keep] for i in range(3)), shape)
        np.minimum.at(dist, flat, d)
        won = d == dist[flat]  # a pair at its sample's new minimum (ties: any of them)
        vec = np.stack([x[i][keep[won]] - near[i][keep[won]] for i in range(3)], axis=1)
        n = normal[tri[keep[won]]]
        height = np.einsum("ij,ij->i", vec, n)
        with np.errstate(divide="ignore", invalid="ignore"):
            off_plane = np.abs(height) > 1e-3 * d[won]
            direction = np.where(off_plane[:, None], np.sign(height)[:, None] * n, np.nan_to_num(vec / d[won, None]))
        away[flat[won]] = direction
        start = stop
    return dist.reshape(shape), away.reshape(*shape, 3)


def _border_labels(labels: np.ndarray) -> np.ndarray:
    faces = [labels[0], labels[-1], labels[:, 0], labels[:, -1], labels[:, :, 0], labels[:, :, -1]]
    found = np.unique(np.concatenate([f.ravel() for f in faces]))
    return found[found > 0]


def fill_open_mesh(mesh: trimesh.Trimesh, resolution: int, face_budget: int, max_gap: float) -> FilledSolid:
    """Rebuild an open mesh as a solid, bridging gaps up to ``max_gap`` (see the module doc).

    Parameters
    ----------
    mesh : triangles, meters; any winding, several pieces, holes, cracks, inner pieces
    resolution : int — field samples along the largest extent (cell = extent / resolution)
    face_budget : int — maximum faces after decimation
    max_gap : float — widest hole or crack bridged, as a share of the largest extent;
        below about two cells the shell alone bridges (``gap_m`` says what was used)
    """
    extent = float(mesh.extents.max())
    pitch = extent / resolution
    shell = _SHELL * pitch
    clearance = max(0.5 * max_gap * extent, shell)  # the flood keeps this far from the surface
    gap_m = 2 * clearance
    pad = int(np.ceil(clearance / pitch)) + 3
    origin, pitch, shape = grid_around(mesh.bounds, resolution, pad)

    v, f = trimesh.remesh.subdivide_to_size(mesh.vertices, mesh.faces, max_edge=4 * pitch, max_iter=16)
    triangles = v[f]
    dist, away = band_distance(triangles, origin, pitch, shape, radius=pitch * 1.0001)

    near = dist <= shell
    to_shell = ndimage.distance_transform_edt(~near, sampling=pitch)
    # distance to the surface: exact within a cell of it, else estimated from the shell's
    magnitude = np.where(np.isfinite(dist), dist, to_shell + 0.5 * shell)
    labels, _ = ndimage.label(~near & (magnitude > clearance), structure=np.ones((3, 3, 3), bool))
    outer = np.isin(labels, _border_labels(labels))
    del labels
    to_outer = ndimage.distance_transform_edt(~outer, sampling=pitch)
    # off the shell the closing decides; on it, the classified sample met walking away from the surface
    inside = ~near & (to_outer > clearance + 0.5 * pitch)
    shell_idx = np.argwhere(near)
    decided = np.zeros(len(shell_idx), bool)
    side = np.zeros(len(shell_idx), bool)
    direction = away[tuple(shell_idx.T)].astype(float)
    dims = np.array(shape)
    for step in _WALK:
        todo = np.flatnonzero(~decided)
        if not len(todo):
            break
        q = np.clip(np.rint(shell_idx[todo] + step * direction[todo]).astype(np.int64), 0, dims - 1)
        q_near = near[tuple(q.T)]
        hit = todo[~q_near]
        side[hit] = inside[tuple(q[~q_near].T)]
        decided[hit] = True
        # heading into another surface before leaving the shell: inside a wall thinner than
        # the shell, or in a crack narrower than it (which the closing fills anyway)
        facing = np.einsum("ij,ij->i", away[tuple(q[q_near].T)], direction[todo[q_near]]) < -0.5
        blocked = todo[q_near][facing]
        side[blocked] = True
        decided[blocked] = True
    inside[tuple(shell_idx.T)] = side
    _vote_undecided(inside, shell_idx[~decided], _decided_grid(near, shell_idx, decided))

    # exact distance near the surface; elsewhere an estimate (only its sign matters off the walls);
    # inside samples on the surface itself (faces shared by two bodies) get a hair inside
    field = np.where(inside, -np.maximum(magnitude, 2e-6 * pitch), magnitude)

    solid = field < -1e-6 * pitch  # inside at the level marching cubes uses (not the samples on the surface)
    enclosed = _enclosed_share(triangles, solid, origin, pitch)
    if not solid.any():
        return FilledSolid(trimesh.Trimesh(), 0.0, enclosed, gap_m)
    surface, dropped = largest_piece(surface_from_field(field, origin, pitch))
    return FilledSolid(decimate(surface, face_budget), dropped, enclosed, gap_m)


def _decided_grid(near: np.ndarray, shell_idx: np.ndarray, decided: np.ndarray) -> np.ndarray:
    """Samples whose side is known: off the shell, or on it and decided by the walk."""
    known = ~near
    known[tuple(shell_idx[decided].T)] = True
    return known


def _vote_undecided(inside: np.ndarray, idx: np.ndarray, known: np.ndarray, rounds: int = 4) -> None:
    """Sides of shell samples the walk left open (on the surface itself, where no direction
    points away from it: faces on grid planes), in place: inside when more of their six
    neighbors of known side are inside than outside; a tie stays outside (a sample on the
    true boundary, where either side puts the surface at the same place)."""
    dims = np.array(inside.shape)
    offsets = np.array([(1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, 1), (0, 0, -1)])
    for _ in range(rounds):
        if not len(idx):
            return
        nb = np.clip(idx[:, None, :] + offsets[None], 0, dims - 1)
        nb_known = known[tuple(nb.reshape(-1, 3).T)].reshape(-1, 6)
        nb_inside = inside[tuple(nb.reshape(-1, 3).T)].reshape(-1, 6)
        vote = (nb_known & nb_inside).sum(axis=1) - (nb_known & ~nb_inside).sum(axis=1)
        settled = (vote != 0) | (nb_known.sum(axis=1) > 0)
        inside[tuple(idx[vote > 0].T)] = True
        known[tuple(idx[settled].T)] = True
        idx = idx[~settled]


def _enclosed_share(triangles: np.ndarray, inside: np.ndarray, origin: np.ndarray, pitch: float) -> float:
    """Share of the triangles' area with an inside sample next to (within one step of) the
    sample nearest to their center: a wall of the solid has inside on one side, an open flap
    or a wall the outside floods around has none."""
    area = trimesh.triangles.area(triangles)
    if not area.sum() > 0:
        return 0.0
    next_to_inside = ndimage.maximum_filter(inside, size=3)
    nearest = np.rint((triangles.mean(axis=1) - origin) / pitch).astype(np.int64)
    nearest = np.clip(nearest, 0, np.array(inside.shape) - 1)
    return float(area[next_to_inside[tuple(nearest.T)]].sum() / area.sum())


def union_of_closed_bodies(mesh: trimesh.Trimesh, resolution: int, face_budget: int) -> tuple[trimesh.Trimesh, float]:
    """The union of several closed bodies: winding-count occupancy on a fine grid, lightly
    smoothed, then marching cubes; the largest piece, decimated.

    Returns
    -------
    mesh : closed, outward-oriented surface of the largest piece, meters
    dropped : float — share of the volume in pieces that were dropped
    """
    bounds = mesh.bounds
    origin, pitch, shape = grid_around(bounds, resolution, pad_cells=2)
    n = max(shape)
    grid = VoxelGrid(n, pitch, origin - 0.5 * pitch)  # voxel centers on the sample points
    occupied = np.zeros((n, n, n), dtype=bool)
    for body in mesh.split(only_watertight=False):
        occupied |= voxelize_solid(body.vertices, body.faces, grid)
    smooth = ndimage.gaussian_filter(occupied.astype(np.float32), sigma=0.7)
    out = surface_from_field(0.5 - smooth, origin, pitch)
    out, dropped = largest_piece(out)
    return decimate(out, face_budget), dropped


def close_surface(
    mesh: trimesh.Trimesh, resolution: int, face_budget: int, max_gap: float, finest_resolution: int = 0
) -> ClosedSurface:
    """One closed outer surface for a mesh: as it is when closed, else rebuilt by :func:`fill_open_mesh`.

    Holes of three or four edges are filled and the winding made consistent first. One
    closed body is kept as it is (decimated to the budget); several closed bodies become
    their union (:func:`union_of_closed_bodies`); anything still
    open is filled. When less than ``MIN_ENCLOSED`` of its area then bounds the solid
    (walls thinner than about a cell vanish, as a hole would leave them), it is filled
    again at ``finest_resolution`` if that is finer.
    """
    mesh = mesh.copy()
    trimesh.repair.fill_holes(mesh)  # closes holes of one or a few missing triangles
    trimesh.repair.fix_normals(mesh)
    with np.errstate(divide="ignore", invalid="ignore"):
        closed = mesh.is_watertight and mesh.body_count == 1 and mesh.volume > 0
    if closed:
        return ClosedSurface(decimate(mesh, face_budget), 0.0, False, 1.0, 0.0, resolution)
    if mesh.is_watertight:
        surface, dropped = union_of_closed_bodies(mesh, resolution, face_budget)
        return ClosedSurface(surface, dropped, False, 1.0, 0.0, resolution)
    filled = fill_open_mesh(mesh, resolution, face_budget, max_gap)
    if filled.enclosed < MIN_ENCLOSED and finest_resolution > resolution:
        finer = fill_open_mesh(mesh, finest_resolution, face_budget, max_gap)
        if finer.enclosed > filled.enclosed:
            filled, resolution = finer, finest_resolution
    return ClosedSurface(filled.mesh, filled.dropped, True, filled.enclosed, filled.gap_m, resolution)
