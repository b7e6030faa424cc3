"""Field grids around a mesh's bounds, and closed surfaces from sampled fields.

A *field* is a function sampled on a regular grid of cubic cells, negative inside a
solid and positive outside (a signed distance, a half-space field, or ``0.5 -``
an occupancy). :func:`grid_around` places the grid; :func:`surface_from_field`
contours it by marching cubes; :func:`largest_piece` and :func:`decimate` finish the
surface the same way for every rebuilt shape.
"""

from __future__ import annotations

import logging
from collections import Counter

import numpy as np
import trimesh

log = logging.getLogger(__name__)


def grid_around(bounds: np.ndarray, resolution: int, pad_cells: int) -> tuple[np.ndarray, float, tuple[int, int, int]]:
    """Sample grid around ``bounds``: cubic cells, ``resolution`` cells along the largest extent.

    Parameters
    ----------
    bounds : (2, 3) float — axis-aligned lower and upper corners, meters
    resolution : int — cells along the largest extent (pitch = largest extent / resolution)
    pad_cells : int — samples added beyond the bounds on every side

    Returns
    -------
    origin : (3,) float — position of sample (0, 0, 0), meters
    pitch : float — sample spacing, meters
    shape : (3,) int — samples per axis
    """
    extent = bounds[1] - bounds[0]
    pitch = float(extent.max()) / resolution
    origin = bounds[0] - pad_cells * pitch
    shape = tuple(int(n) for n in np.ceil(extent / pitch).astype(int) + 2 * pad_cells + 1)
    return origin, pitch, shape


def surface_from_field(field: np.ndarray, origin: np.ndarray, pitch: float, level: float = 0.0) -> trimesh.Trimesh:
    """Closed surface of ``{field < level}`` by marching cubes (Lewiner).

    Parameters
    ----------
    field : (a, b, c) float — samples, negative inside; must be positive on the border
    origin : (3,) float — position of sample (0, 0, 0), meters
    pitch : float — sample spacing, meters
    """
    from skimage.measure import marching_cubes

    # samples exactly on the level (plateaus after morphology, vertices on the grid)
    # make marching cubes emit non-manifold pieces; a level a hair inside avoids them
    level = level - 1e-6 * pitch
    verts, faces, _, _ = marching_cubes(
        field, level=level, spacing=(pitch,) * 3, method="lewiner", allow_degenerate=False
    )
    # marching cubes shares its vertices already; trimesh's merge (process=True) would fuse the pairs closer than its
    # tolerance (1e-8 m) that a sample on a face plane leaves, dropping triangles and opening a closed solid (a
    # pyramid whose faces pass through samples came out in 6,700 pieces)
    mesh = trimesh.Trimesh(verts + origin, faces, process=False)
    trimesh.repair.fix_normals(mesh)
    return mesh


def largest_piece(mesh: trimesh.Trimesh) -> tuple[trimesh.Trimesh, float]:
    """The connected piece with the largest volume, and the share of volume dropped."""
    pieces = mesh.split(only_watertight=False)
    if len(pieces) <= 1:
        return mesh, 0.0
    with np.errstate(divide="ignore", invalid="ignore"):  # slivers of zero volume warn in trimesh
        volumes = np.array([abs(p.volume) for p in pieces])
    best = int(np.argmax(volumes))
    return pieces[best], float(1.0 - volumes[best] / volumes.sum())


#: Decimations that returned a mesh over its face budget in this process, by cause: ``raised`` (the decimator
#: raised at every setting) and ``opened`` (no setting kept the surface closed and in one piece). A stage whose
#: meshes are decimated in this process reports them (:func:`over_budget_counts`); one whose workers decimate
#: counts its outputs' faces against the budget.
_over_budget: Counter[str] = Counter()


def over_budget_counts() -> dict[str, int]:
    """How many :func:`decimate` calls in this process returned a mesh over its face budget, by cause
    (``raised``, ``opened``), since the process started or :func:`reset_over_budget_counts`."""
    return dict(_over_budget)


def reset_over_budget_counts() -> None:
    """Start :func:`over_budget_counts` from zero (a stage does at its start)."""
    _over_budget.clear()


def decimate(mesh: trimesh.Trimesh, face_budget: int) -> trimesh.Trimesh:
    """Quadric decimation to at most ``face_budget`` faces, kept only if still closed and in one piece.

    fast-simplification sometimes pinches a few edges into non-manifold ones, at
    some aggression settings and not others; settings are tried in turn (3, 7, 1,
    0; the gentlest may stop above the budget) and the first result that is
    closed and in one piece is kept. A setting at which the decimator raises is
    skipped the same way. If no setting gives one, the undecimated mesh (closed,
    valid, over the budget) is returned, counted (:func:`over_budget_counts`) and,
    when the decimator raised, logged as a warning naming the exception: a shape
    is not lost for the decimator's sake, and not silently larger either.

    Parameters
    ----------
    mesh : trimesh.Trimesh — a closed surface, meters (not modified)
    face_budget : int — the most faces wanted
    """
    if len(mesh.faces) <= face_budget:
        return mesh
    errors: list[str] = []
    for aggression in (3, 7, 1, 0):
        try:
            small = mesh.simplify_quadric_decimation(face_count=face_budget, aggression=aggression)
        except Exception as exc:  # noqa: BLE001 - any failure of the decimator: try the next setting, then report
            errors.append(f"{type(exc).__name__}: {exc}")
            continue
        small.merge_vertices()
        small.remove_unreferenced_vertices()
        if small.is_watertight and small.body_count == 1 and small.volume > 0:
            trimesh.repair.fix_normals(small)
            return small
    if len(errors) == 4:
        _over_budget["raised"] += 1
        log.warning(
            "decimate: the decimator failed at every setting (%s); keeping the mesh of %d faces, over the budget of %d",
            errors[0],
            len(mesh.faces),
            face_budget,
        )
    else:
        _over_budget["opened"] += 1
        log.debug("decimate: no setting kept the surface closed; keeping the mesh of %d faces", len(mesh.faces))
    return mesh
