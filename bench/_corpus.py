"""Shared by the bench scripts: the first N default shapes, ingested in memory with the library."""

from __future__ import annotations

from dataclasses import dataclass

import trimesh
from joblib import Parallel, delayed

from graspaug.geometry.loading import MeshRejected, load_shape
from graspaug.geometry.prepare import SurfaceSettings, prepare_shape
from graspaug.geometry.solid import ConvexPart
from graspaug.io.sources import Source, pybullet_sources


@dataclass
class BenchShape:
    shape_id: str
    mesh: trimesh.Trimesh  # normalized closed outer surface, meters
    parts: list[ConvexPart]  # the source's convex parts in the same normalized frame


def _one(source: Source, settings: SurfaceSettings) -> BenchShape | None:
    try:
        loaded = load_shape(source.path, source.unit_scale)
        prepared = prepare_shape(loaded, settings)
    except MeshRejected:
        return None
    norm = prepared.normalization
    return BenchShape(source.shape_id, prepared.mesh, [p.scaled(norm.scale, norm.offset) for p in loaded.parts])


def default_shapes(n: int | None, n_jobs: int = 2) -> list[BenchShape]:
    """The first ``n`` shapes of the default corpus (None: all), as the ingest stage's defaults make them."""
    settings = SurfaceSettings()
    shapes = Parallel(n_jobs=n_jobs)(delayed(_one)(s, settings) for s in pybullet_sources(n))
    return [s for s in shapes if s is not None]
