"""From a loaded source file to the normalized closed outer surface every stage uses."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import trimesh

from graspaug.geometry.loading import LoadedShape, MeshRejected
from graspaug.geometry.normalize import Normalization, normalization
from graspaug.geometry.solid import outer_surface_of_mesh, outer_surface_of_parts, resolution_for_parts
from graspaug.geometry.settings import SurfaceSettings


@dataclass
class PreparedShape:
    """A normalized closed outer surface and how it was made from the source."""

    mesh: trimesh.Trimesh  # normalized frame, meters, outward normals
    normalization: Normalization  # loaded frame -> normalized frame
    n_parts: int  # convex parts used (0 when rebuilt from the triangles)
    resolution: int  # field samples along the largest extent that were used
    dropped_volume: float  # share of the solid's volume not in the kept piece


def prepare_shape(loaded: LoadedShape, settings: SurfaceSettings) -> PreparedShape:
    """Rebuild one closed, one-piece outer surface, then center and scale it.

    Raises
    ------
    MeshRejected
        when the rebuilt solid has no volume or is split into pieces of which the
        largest misses more than ``settings.max_dropped`` of the volume.
    """
    if loaded.parts:
        resolution = resolution_for_parts(loaded.parts, settings.resolution, settings.finest_resolution, settings.cells_per_thickness)
        surface, dropped = outer_surface_of_parts(loaded.parts, resolution, settings.face_budget)
    else:
        resolution = settings.resolution
        surface, dropped = outer_surface_of_mesh(loaded.mesh, resolution, settings.face_budget)
    if len(surface.faces) == 0 or not surface.volume > 0:
        raise MeshRejected("degenerate: the rebuilt solid has no volume")
    if dropped > settings.max_dropped:
        raise MeshRejected(f"in pieces: {dropped:.0%} of the volume lies outside the largest piece")
    if not surface.is_watertight:
        raise MeshRejected("could not close the surface")
    norm = normalization(surface, settings.size_rule, settings.size_m)
    mesh = norm.apply(surface)
    if not np.isfinite(mesh.vertices).all():
        raise MeshRejected("degenerate: normalization produced non-finite coordinates")
    return PreparedShape(mesh=mesh, normalization=norm, n_parts=len(loaded.parts), resolution=resolution, dropped_volume=dropped)
