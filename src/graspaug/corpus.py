"""One source file → one row of the shape table (its mesh written), and the train/test split."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from graspaug.geometry.loading import MeshRejected, load_shape, sha256_of
from graspaug.geometry.prepare import SurfaceSettings, prepare_shape
from graspaug.io.meshes import mesh_path, write_mesh
from graspaug.io.sources import Source


def ingest_source(source: Source, max_faces: int, max_file_mb: float, settings: SurfaceSettings, out_dir: Path) -> dict:
    """Process one source: a shapes row (``ok``) or a rejects row (``reason``)."""
    row: dict = {"shape_id": source.shape_id, "source": source.name}
    try:
        row["source_sha256"] = sha256_of(source.path)
        loaded = load_shape(source.path, source.unit_scale, max_faces, max_file_mb)
        prepared = prepare_shape(loaded, settings)
    except MeshRejected as exc:
        return {**row, "ok": False, "reason": str(exc)}
    except OSError as exc:
        return {**row, "ok": False, "reason": f"unreadable: {type(exc).__name__}: {exc.strerror or exc}"}
    mesh, norm = prepared.mesh, prepared.normalization
    write_mesh(mesh, mesh_path(out_dir, source.shape_id))
    extents = mesh.extents
    return {
        **row,
        "ok": True,
        "faces": len(mesh.faces),
        "vertices": len(mesh.vertices),
        "watertight": bool(mesh.is_watertight),
        "volume": float(mesh.volume),
        "extent_x": float(extents[0]),
        "extent_y": float(extents[1]),
        "extent_z": float(extents[2]),
        # normalized = scale * (source file coordinates) + offset, meters
        "scale": source.unit_scale * norm.scale,
        "offset_x": float(norm.offset[0]),
        "offset_y": float(norm.offset[1]),
        "offset_z": float(norm.offset[2]),
        "n_parts": prepared.n_parts,
        "surface_resolution": prepared.resolution,
        "dropped_volume": prepared.dropped_volume,
        "closed_by": prepared.closed_by,  # as_is, merged (vertices merged by position) or filled (open mesh filled)
        "hull_fill": prepared.hull_fill,  # volume / convex-hull volume (a hollow shell shows as a small value)
    }


def assign_split(shape_ids: list[str], test_fraction: float, seed: int) -> dict[str, str]:
    """Seeded shuffle of the sorted ids; the first ``round(test_fraction * n)`` are ``test``."""
    ids = sorted(shape_ids)
    order = np.random.default_rng(seed).permutation(len(ids))
    n_test = int(round(test_fraction * len(ids)))
    return {ids[i]: ("test" if rank < n_test else "train") for rank, i in enumerate(order)}


def closing_summary(shapes: pd.DataFrame) -> str:
    """One line on how the corpus was closed: counts of ``closed_by`` and the ``hull_fill`` spread."""
    closed = shapes["closed_by"].value_counts()
    lowest = shapes.loc[shapes["hull_fill"].idxmin()]
    return (
        f"closed_by as_is {closed.get('as_is', 0)}, merged {closed.get('merged', 0)}, filled {closed.get('filled', 0)}; "
        f"hull_fill median {shapes['hull_fill'].median():.2f}, lowest {lowest['hull_fill']:.2f} ({lowest['shape_id']})"
    )
