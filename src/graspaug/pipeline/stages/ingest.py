"""Stage ``ingest``: source meshes → normalized closed outer surfaces, an objects table, a reject table.

Outputs: ``data/shapes/<shape_id>.ply``, ``data/objects.parquet`` (no train/test split: the ``split`` stage adds it),
``data/rejects.parquet``.
"""

from __future__ import annotations

import logging
import time
from collections import Counter

import pandas as pd

from graspaug.augment.corpus import closing_summary, flag_duplicates, ingest_source, reject_lines
from graspaug.io.atomic import atomic_path
from graspaug.io.settings import CorpusSettings
from graspaug.io.sources import folder_sources, pybullet_sources
from graspaug.io.tables import write_table
from graspaug.pipeline.params.base import params_model
from graspaug.pipeline.params.ingest import IngestParams
from graspaug.pipeline.params.voxelize import VoxelizeParams
from graspaug.pipeline.paths import OBJECTS_TABLE, REJECTS_TABLE, SHAPES_DIR
from graspaug.pipeline.stages import StageError

log = logging.getLogger(__name__)

Params = params_model(
    "The params the `ingest` stage reads.", data=CorpusSettings, ingest=IngestParams, voxelize=VoxelizeParams
)


def run(params: Params) -> None:
    """Run the stage with ``params``; writes the three outputs atomically."""
    from graspaug.parallel import parallel_map

    start = time.perf_counter()
    data, cfg = params.data, params.ingest
    grid = (params.voxelize.resolution, params.voxelize.margin)  # the AutoEncoder's grid: no empty shape reaches it
    if data.source == "pybullet":
        sources = pybullet_sources(data.limit)
    else:
        sources = folder_sources(data.path, data.unit_scale, data.limit)
    if not sources:
        raise StageError(f"no mesh files found for data.source={data.source}")

    with atomic_path(SHAPES_DIR, directory=True) as tmp_dir:
        tmp_dir = tmp_dir.resolve()  # worker processes may have another working directory
        rows = parallel_map(
            lambda s: ingest_source(s, cfg.max_faces, cfg.max_file_mb, cfg.surface, tmp_dir, grid, cfg.min_voxels),
            sources,
            params.workers,
            "ingest",
        )
        kept = [r for r in rows if r.pop("ok")]
        shapes = flag_duplicates(
            pd.DataFrame(kept).drop(columns="_occupancy", errors="ignore"), [r["_occupancy"] for r in kept]
        )
        rejects = pd.DataFrame(
            [r for r in rows if "reason" in r], columns=["shape_id", "source", "source_sha256", "reason"]
        )
        if len(shapes) < cfg.min_shapes:
            reasons = "; ".join(f"{n}× {r}" for r, n in Counter(rejects["reason"]).most_common(3))
            raise StageError(
                f"only {len(shapes)} of {len(sources)} shapes are usable, "
                f"ingest.min_shapes={cfg.min_shapes} ({reasons})"
            )
        shapes["origin"] = "original"
        write_table(shapes, OBJECTS_TABLE)
        write_table(rejects, REJECTS_TABLE)

    for line in reject_lines(rejects, REJECTS_TABLE):
        log.info("ingest: %s", line)
    log.info("ingest: %s", closing_summary(shapes))
    kinds = shapes["duplicate_kind"].value_counts()
    log.info(
        "ingest: %d duplicates kept and flagged (%d exact, %d same geometry), each to go to its original's split",
        int((shapes["duplicate_of"] != "").sum()),
        kinds.get("exact", 0),
        kinds.get("geometry", 0),
    )
    log.info(
        "ingest: %d shapes, %d rejected, %d/%d watertight, median %d faces, %d over the face "
        "budget of %d (not decimated: the decimator failed or would open the surface), in %.1f s",
        len(shapes),
        len(rejects),
        int(shapes["watertight"].sum()),
        len(shapes),
        int(shapes["faces"].median()),
        int((shapes["faces"] > cfg.surface.face_budget).sum()),
        cfg.surface.face_budget,
        time.perf_counter() - start,
    )


if __name__ == "__main__":
    from graspaug.pipeline.entry import stage_main

    stage_main(__spec__.name)
