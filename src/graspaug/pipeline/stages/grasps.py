"""Stage ``grasps``: antipodal grasps on every shape of a corpus, labelled by robust Ferrari-Canny.

``dvc.yaml`` runs it once per corpus (``grasps@original``; generated shapes get their own).
Outputs: ``data/grasps/<corpus>.parquet``, one row per grasp: ``shape_id``, ``grasp_id``,
``center_{x,y,z}``, ``axis_{x,y,z}`` (unit, jaw 1 → jaw 2), contacts ``p1_*``, ``p2_*`` with
outward normals ``n1_*``, ``n2_*`` (m, in the shape's normalized frame), ``width`` (m),
``eps`` (ε of the grasp as sampled), ``eps_mean`` / ``eps_std`` (robust ε over perturbations),
``success`` (``eps_mean > threshold``); ``metrics/grasps/<corpus>.json`` (shapes, positive share) and
``reports/grasps/<corpus>.json`` (every count and share).
"""

from __future__ import annotations

import logging
import time

from graspaug.grasping.labelled import grasps_headline, grasps_of_shapes, grasps_summary
from graspaug.io.tables import read_table, write_json, write_table
from graspaug.pipeline.params.base import params_model
from graspaug.pipeline.params.grasps import GraspsParams
from graspaug.pipeline.paths import grasps_metrics, grasps_report, grasps_table, timing_file
from graspaug.pipeline.stages import corpus_paths

log = logging.getLogger(__name__)

Params = params_model("The params the `grasps` stage reads.", grasps=GraspsParams)


def run(params: Params, corpus: str = "original") -> None:
    table_path, mesh_dir, suffix = corpus_paths(corpus)
    start = time.perf_counter()
    shape_ids = list(read_table(table_path)["shape_id"])
    table, reasons = grasps_of_shapes(
        mesh_dir, shape_ids, suffix, params.grasps, params.seed, params.workers, f"grasps ({corpus})"
    )
    for shape_id, reason in reasons.items():
        log.warning("grasps: %s has no grasp: %s", shape_id, reason)
    write_table(table, grasps_table(corpus))

    seconds = time.perf_counter() - start
    summary = grasps_summary(table, shape_ids)
    write_json(summary, grasps_report(corpus))
    write_json(grasps_headline(summary), grasps_metrics(corpus))
    write_json({"seconds": round(seconds, 1)}, timing_file("grasps", corpus))
    log.info(
        "grasps (%s): %d grasps on %d shapes (%d without), %.1f%% successful, in %.1f s",
        corpus,
        len(table),
        len(shape_ids),
        summary["shapes_without_grasps"],
        100 * (summary["success_share"] or 0),
        seconds,
    )


if __name__ == "__main__":
    import typer

    from graspaug.pipeline.entry import stage_main

    corpus = typer.Option("original", "--corpus", "-c", help="`original` (ingested corpus) or `gen_<B>` (generated).")
    stage_main(__spec__.name, corpus=(str, corpus))
