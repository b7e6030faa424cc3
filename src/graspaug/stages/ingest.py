"""Stage ``ingest``: source meshes → normalized closed outer surfaces, a shape table, a reject table.

Outputs: ``data/shapes/<shape_id>.ply``, ``data/shapes.parquet``, ``data/rejects.parquet``.
"""
from __future__ import annotations

import logging
import time
from collections import Counter
from pathlib import Path

import numpy as np
import pandas as pd

from graspaug.config import IngestParams, Params
from graspaug.geometry.loading import MeshRejected, load_shape, sha256_of
from graspaug.geometry.prepare import SurfaceSettings, prepare_shape
from graspaug.io.atomic import atomic_path
from graspaug.io.meshes import mesh_path, write_mesh
from graspaug.io.sources import Source, folder_sources, pybullet_sources
from graspaug.io.tables import write_table
from graspaug.paths import REJECTS_TABLE, SHAPES_DIR, SHAPES_TABLE
from graspaug.stages import StageError

log = logging.getLogger(__name__)


def _ingest_one(source: Source, max_faces: int, max_file_mb: float, settings: SurfaceSettings, out_dir: Path) -> dict:
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
        "closed_by": prepared.closed_by,
        "hull_fill": prepared.hull_fill,
    }


def surface_settings(cfg: IngestParams) -> SurfaceSettings:
    """The library's settings from the ``ingest`` params section."""
    return SurfaceSettings(
        resolution=cfg.surface_resolution,
        finest_resolution=cfg.finest_surface_resolution,
        cells_per_thickness=cfg.cells_per_thickness,
        face_budget=cfg.face_budget,
        size_rule=cfg.size_rule,
        size_m=cfg.size_m,
        max_dropped=cfg.max_dropped,
        max_gap=cfg.max_gap,
    )


def assign_split(shape_ids: list[str], test_fraction: float, seed: int) -> dict[str, str]:
    """Seeded shuffle of the sorted ids; the first ``round(test_fraction * n)`` are ``test``."""
    ids = sorted(shape_ids)
    order = np.random.default_rng(seed).permutation(len(ids))
    n_test = int(round(test_fraction * len(ids)))
    return {ids[i]: ("test" if rank < n_test else "train") for rank, i in enumerate(order)}


def run(params: Params) -> None:
    """Run the stage with ``params``; writes the three outputs atomically."""
    from graspaug.parallel import parallel_map

    start = time.perf_counter()
    data, cfg = params.data, params.ingest
    if data.source == "pybullet":
        sources = pybullet_sources(data.limit)
    else:
        sources = folder_sources(data.path, data.unit_scale, data.limit)
    if not sources:
        raise StageError(f"no mesh files found for data.source={data.source}")
    settings = surface_settings(cfg)

    with atomic_path(SHAPES_DIR, directory=True) as tmp_dir:
        tmp_dir = tmp_dir.resolve()  # worker processes may have another working directory
        rows = parallel_map(lambda s: _ingest_one(s, cfg.max_faces, cfg.max_file_mb, settings, tmp_dir), sources, params.workers, "ingest")
        shapes = pd.DataFrame([r for r in rows if r.pop("ok")])
        rejects = pd.DataFrame([r for r in rows if "reason" in r], columns=["shape_id", "source", "source_sha256", "reason"])
        if len(shapes) < cfg.min_shapes:
            reasons = "; ".join(f"{n}× {r}" for r, n in Counter(rejects["reason"]).most_common(3))
            raise StageError(f"only {len(shapes)} of {len(sources)} shapes are usable, ingest.min_shapes={cfg.min_shapes} ({reasons})")
        split = assign_split(list(shapes["shape_id"]), cfg.test_fraction, params.seed)
        shapes["split"] = shapes["shape_id"].map(split)
        shapes["origin"] = "original"
        write_table(shapes, SHAPES_TABLE)
        write_table(rejects, REJECTS_TABLE)

    for reason, n in Counter(rejects["reason"]).most_common():
        log.info("rejected %d: %s", n, reason)
    closed = shapes["closed_by"].value_counts()
    log.info(
        "ingest: closed_by as_is %d, merged %d, filled %d; hull_fill median %.2f, min %.2f (%s)",
        closed.get("as_is", 0), closed.get("merged", 0), closed.get("filled", 0),
        shapes["hull_fill"].median(), shapes["hull_fill"].min(), shapes.loc[shapes["hull_fill"].idxmin(), "shape_id"],
    )
    counts = shapes["split"].value_counts()
    log.info(
        "ingest: %d shapes (%d train, %d test), %d rejected, %d/%d watertight, median %d faces, in %.1f s",
        len(shapes), counts.get("train", 0), counts.get("test", 0), len(rejects),
        int(shapes["watertight"].sum()), len(shapes), int(shapes["faces"].median()), time.perf_counter() - start,
    )
