"""From a loaded source file to the normalized closed outer surface every stage uses."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import trimesh

from graspaug.geometry.closing import MIN_ENCLOSED, close_surface
from graspaug.geometry.loading import LoadedShape, MeshRejected
from graspaug.geometry.normalize import Normalization, centering, normalization
from graspaug.geometry.settings import SurfaceSettings
from graspaug.geometry.solid import outer_surface_of_parts, resolution_for_parts


@dataclass
class PreparedShape:
    """A normalized closed outer surface and how it was made from the source."""

    mesh: trimesh.Trimesh  # normalized frame, meters, outward normals
    normalization: Normalization  # loaded frame -> normalized frame
    n_parts: int  # convex parts used (0 when rebuilt from the triangles)
    resolution: int  # field samples along the largest extent that were used
    dropped_volume: float  # share of the solid's volume not in the kept piece
    closed_by: str = "as_is"  # as_is, merged (vertices merged by position) or filled (open mesh filled)
    hull_fill: float = 1.0  # volume / convex hull volume


FIT_SHARE = 0.9  # size `fit`: a shape too wide for the gripper is scaled until its narrowest side is this share of it
#: How many times too wide for the gripper a shape must be for its reject to name the likely unit mistake.
UNIT_MISTAKE = 100.0
UNIT_HINT = (
    "millimetres read as metres? give the unit: --unit-scale 0.001 (evaluate, study real-picks --objects), "
    "data.unit_scale: 0.001 (ingest)"
)


def too_wide(smallest: float, max_width: float, why: str = "") -> MeshRejected:
    """The reject of a shape whose narrowest side ``smallest`` (m) exceeds ``max_width`` (m), ``why`` appended, and
    the likely unit mistake (:data:`UNIT_HINT`) named when it is :data:`UNIT_MISTAKE` times too wide or more."""
    hint = f"; {UNIT_HINT}" if smallest >= UNIT_MISTAKE * max_width else ""
    return MeshRejected(
        f"too large for the gripper: smallest side {smallest:.3f} m > max_width={max_width:g} m{why}{hint}"
    )


def _check_real_size(surface: trimesh.Trimesh, settings: SurfaceSettings) -> None:
    """Raise :class:`MeshRejected` when a shape kept at its real size is too small (largest extent below
    ``settings.min_extent``) or too large for the gripper (the smallest side of its oriented bounding box, m,
    above ``settings.max_width``)."""
    largest = float(surface.extents.max())
    if largest < settings.min_extent:
        raise MeshRejected(f"too small: largest extent {largest:.4f} m < min_extent={settings.min_extent:g} m")
    smallest = float(np.min(surface.bounding_box_oriented.primitive.extents))
    if smallest > settings.max_width:
        raise too_wide(smallest, settings.max_width)


def prepare_shape(loaded: LoadedShape, settings: SurfaceSettings) -> PreparedShape:
    """Rebuild one closed, one-piece outer surface, then center it and (``settings.size``: ``normalize``) scale it
    by the size rule, (``real``) keep its size, or (``fit``) keep its size unless the gripper cannot close across it,
    when it is scaled down until the smallest side of its oriented bounding box is :data:`FIT_SHARE` of
    ``settings.max_width`` (rejected when that would scale it by less than ``settings.fit_min_scale``).

    Raises
    ------
    MeshRejected
        when an open mesh can only be closed by bridging a hole wider than
        ``settings.max_gap`` (more than ``1 - MIN_ENCLOSED`` of its area bounds nothing),
        when the rebuilt solid has no volume or is split into pieces of which the
        largest misses more than ``settings.max_dropped`` of the volume, and at real size when it is
        too small or too large for the gripper (:func:`_check_real_size`).
    """
    closed_by = loaded.closed_by
    if loaded.parts:
        resolution = resolution_for_parts(
            loaded.parts, settings.resolution, settings.finest_resolution, settings.cells_per_thickness
        )
        surface, dropped = outer_surface_of_parts(loaded.parts, resolution, settings.face_budget)
    else:
        resolution = settings.resolution
        closed = close_surface(
            loaded.mesh, resolution, settings.face_budget, settings.max_gap, settings.finest_resolution
        )
        surface, dropped, resolution = closed.mesh, closed.dropped, closed.resolution
        if closed.filled:
            closed_by = "filled"
            if closed.enclosed < MIN_ENCLOSED:
                raise MeshRejected(
                    f"open: {1 - closed.enclosed:.0%} of the surface encloses nothing, a hole wider than "
                    f"max_gap={settings.max_gap:g} of the largest extent ({1000 * closed.gap_m:.1f} mm) would have to "
                    "be bridged"
                )
    if len(surface.faces) == 0 or not surface.volume > 0:
        raise MeshRejected("degenerate: the rebuilt solid has no volume")
    if dropped > settings.max_dropped:
        raise MeshRejected(f"in pieces: {dropped:.0%} of the volume lies outside the largest piece")
    if not surface.is_watertight:
        raise MeshRejected("could not close the surface")
    if settings.size == "fit":  # real size, but a shape too wide for the gripper shrinks until it fits
        smallest = float(np.min(surface.bounding_box_oriented.primitive.extents))
        scale = min(1.0, FIT_SHARE * settings.max_width / smallest)
        if scale < settings.fit_min_scale:
            raise too_wide(
                smallest, settings.max_width, f", and fitting would scale it by {scale:.3g} < {settings.fit_min_scale}"
            )
        norm = Normalization(scale=scale, offset=scale * centering(surface).offset)
        _check_real_size(norm.apply(surface), settings)
    elif settings.size == "real":
        norm = centering(surface)
        _check_real_size(surface, settings)
    else:
        norm = normalization(surface, settings.size_rule, settings.size_m)
    mesh = norm.apply(surface)
    if not np.isfinite(mesh.vertices).all():
        raise MeshRejected("degenerate: normalization produced non-finite coordinates")
    hull_fill = float(mesh.volume / mesh.convex_hull.volume)
    return PreparedShape(
        mesh=mesh,
        normalization=norm,
        n_parts=len(loaded.parts),
        resolution=resolution,
        dropped_volume=dropped,
        closed_by=closed_by,
        hull_fill=hull_fill,
    )
