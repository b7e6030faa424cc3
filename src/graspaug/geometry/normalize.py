"""Placing a shape in its normalized frame: center of mass at the origin, graspable size (or its own size)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import trimesh

SIZE_RULES = ("min", "mid", "max")


@dataclass(frozen=True)
class Normalization:
    """The similarity ``x -> scale * x + offset`` from the loaded frame (meters) to the normalized one."""

    scale: float
    offset: np.ndarray  # (3,) meters

    def apply(self, mesh: trimesh.Trimesh) -> trimesh.Trimesh:
        """A normalized copy of ``mesh``."""
        out = mesh.copy()
        out.apply_scale(self.scale)
        out.apply_translation(self.offset)
        return out


def _center(mesh: trimesh.Trimesh) -> np.ndarray:
    """(3,) m: the center of mass, or the bounding-box center if the mesh is not closed."""
    return np.asarray(mesh.center_mass if mesh.is_watertight and mesh.volume > 0 else mesh.bounds.mean(axis=0), float)


def normalization(mesh: trimesh.Trimesh, size_rule: str, size_m: float) -> Normalization:
    """Move the center of mass (bounding-box center if the mesh is not closed) to the origin
    and scale uniformly so the chosen extent equals ``size_m``.

    Parameters
    ----------
    mesh : the shape, meters
    size_rule : which axis-aligned extent is set: ``min``, ``mid`` (the middle one) or ``max``
    size_m : float — that extent after scaling, meters
    """
    if size_rule not in SIZE_RULES:
        raise ValueError(f"size_rule must be one of {SIZE_RULES}, got {size_rule!r}")
    extent = np.sort(mesh.extents)[SIZE_RULES.index(size_rule)]
    scale = float(size_m / extent)
    return Normalization(scale=scale, offset=-scale * _center(mesh))


def centering(mesh: trimesh.Trimesh) -> Normalization:
    """Move the center of mass (bounding-box center if the mesh is not closed) to the origin and keep the
    shape's real size (scale 1): the normalization of ``ingest.surface.size: real``."""
    return Normalization(scale=1.0, offset=-_center(mesh))
