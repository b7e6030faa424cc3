"""Stage ``render``: Dex-Net 2.0 style depth crops of every table-parallel grasp of a corpus.

``dvc.yaml`` runs it per corpus (``render@original``: train and test shapes;
``render_generated@B``: the shapes generated for base size B). For each shape: its stable
resting poses, random camera views, each grasp whose jaw axis lies within
``axis_tolerance_deg`` of the table, a 96×96 crop around it turned so the jaws are horizontal,
averaged down to 32×32, and an approach collision check of the Panda.

Outputs ``data/gqcnn/<corpus>/`` (see :mod:`graspaug.io.gqcnn`), its ``index.parquet`` with
one row per datapoint: ``shard``, ``row``, ``shape_id``, ``origin``, ``split``, ``base_size``
(generated only), ``pool`` and ``order`` (generated only: which pool and position in it),
``grasp_id``, ``pose_id``, ``pose_probability``, ``image_id``, ``camera_height`` (m),
``camera_tilt`` (deg), ``center_u`` / ``center_v`` (px in the full image), ``angle`` (rad, jaw
axis in the image), ``z`` (m, gripper depth), ``width_px`` (open jaws in image px),
``collision_free``, ``eps`` (robust ε), ``success`` (ε > threshold of the grasps stage),
``label`` (= collision_free and success); ``metrics/render/<corpus>.json`` (shapes, datapoints, positive
share); ``reports/render/<corpus>/summary.json`` (every count and share) and ``examples.png``.
"""

from __future__ import annotations

import json
import logging
import time

import numpy as np
import pandas as pd

from graspaug.io.atomic import atomic_path
from graspaug.io.gqcnn import write_grasp_images
from graspaug.io.tables import read_table, write_json
from graspaug.pipeline.params.base import params_model
from graspaug.pipeline.params.grasps import GraspsParams
from graspaug.pipeline.params.render import RenderParams
from graspaug.pipeline.paths import gqcnn_dir, grasps_table, render_examples, render_metrics, render_report, timing_file
from graspaug.pipeline.stages import StageError, corpus_paths
from graspaug.render.corpus_dataset import (
    datapoints_table,
    dataset_info,
    example_crops,
    render_corpus,
    render_headline,
    render_summary,
    with_pool_columns,
)
from graspaug.render.dataset import datapoints_index

log = logging.getLogger(__name__)

Params = params_model("The params the `render` stage reads.", render=RenderParams, grasps=GraspsParams)


def run(params: Params, corpus: str = "original") -> None:
    from graspaug.plots import crop_grid

    table_path, mesh_dir, suffix = corpus_paths(corpus)
    start = time.perf_counter()
    cfg, hand, threshold = params.render, params.grasps.gripper, params.grasps.threshold
    shapes = with_pool_columns(read_table(table_path))
    grasps = read_table(grasps_table(corpus))
    label = f"render ({corpus})"
    by_shape, results = render_corpus(shapes, grasps, mesh_dir, suffix, cfg, hand, params.seed, params.workers, label)

    images, parts, skipped, n_rays, n_poses = datapoints_index(shapes, by_shape, results, threshold)
    if not parts:
        raise StageError(f"{label}: no shape gave a datapoint; reasons: {sorted({s['reason'] for s in skipped})[:3]}")
    index, images = datapoints_table(parts), np.concatenate(images)
    with atomic_path(gqcnn_dir(corpus), directory=True) as folder:
        write_grasp_images(folder, images, index, cfg.shard_rows)
        (folder / "dataset.json").write_text(json.dumps(dataset_info(corpus, cfg, hand, threshold), indent=2) + "\n")
        pd.DataFrame(skipped, columns=["shape_id", "reason"]).to_parquet(folder / "skipped.parquet", index=False)

    seconds = time.perf_counter() - start
    summary = render_summary(len(shapes), parts, skipped, index, n_rays, n_poses)
    write_json(summary, render_report(corpus))
    write_json(render_headline(summary), render_metrics(corpus))
    write_json(
        {"seconds": round(seconds, 1), "datapoints_per_second": round(len(index) / seconds, 1)},
        timing_file("render", corpus),
    )

    chosen, titles, jaws = example_crops(index, cfg.n_examples, params.seed, cfg.crop.factor)
    crop_grid(
        images[chosen],
        titles,
        jaws,
        render_examples(corpus),
        f"{label}: positives (+) then negatives (-); red ticks: open jaws; 'hit': approach collides",
    )
    log.info(
        "render (%s): %d datapoints from %d shapes (%d skipped), %.1f%% positive (%.1f%% collision free), %.1f s",
        corpus,
        len(index),
        len(parts),
        len(skipped),
        100 * summary["positive_share"],
        100 * summary["collision_free_share"],
        seconds,
    )


if __name__ == "__main__":
    import typer

    from graspaug.pipeline.entry import stage_main

    corpus = typer.Option("original", "--corpus", "-c", help="`original` (train and test) or `gen_<B>` (generated).")
    stage_main(__spec__.name, corpus=(str, corpus))
