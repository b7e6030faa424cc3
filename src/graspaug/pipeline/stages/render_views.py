"""Stage ``render_views``: the original shapes seen from ``gqcnn.extra_views`` more camera views per stable pose.

The same shapes, grasps, poses and crops as ``render@original``, but each view from the shape's ``render-views``
random stream (new camera seeds), ``gqcnn.extra_views`` views per pose: the datapoints the ``views`` networks add to
their base shapes (:func:`graspaug.training.gqcnn_data.views_rows`). Per object, with no split: every draw shares it.
With ``gqcnn.extra_views`` 0 (every profile but those that train a ``views`` network) it writes an empty corpus.

Outputs ``data/gqcnn/views/`` (a GQ-CNN dataset folder as ``render`` writes, :mod:`graspaug.io.gqcnn`),
``reports/timing/render/views.json``.
"""

from __future__ import annotations

import dataclasses
import json
import logging
import time

import numpy as np
import pandas as pd

from graspaug.io.atomic import atomic_path
from graspaug.io.gqcnn import write_grasp_images
from graspaug.io.tables import read_table, write_json
from graspaug.pipeline.params.base import params_model
from graspaug.pipeline.params.gqcnn import GQCNNParams
from graspaug.pipeline.params.grasps import GraspsParams
from graspaug.pipeline.params.render import RenderParams
from graspaug.pipeline.paths import gqcnn_dir, grasps_table, timing_file
from graspaug.pipeline.stages import corpus_paths
from graspaug.render.corpus_dataset import datapoints_table, dataset_info, render_corpus, with_pool_columns
from graspaug.render.dataset import datapoints_index

log = logging.getLogger(__name__)

Params = params_model(
    "The params the `render_views` stage reads.", render=RenderParams, grasps=GraspsParams, gqcnn=GQCNNParams
)


def run(params: Params) -> None:
    start, views = time.perf_counter(), params.gqcnn.extra_views
    hand, threshold = params.grasps.gripper, params.grasps.threshold
    cfg = dataclasses.replace(params.render, images_per_pose=max(views, 1))
    images, index, skipped = np.zeros((0, cfg.crop.out_size, cfg.crop.out_size), np.float32), None, []
    if views:
        table_path, mesh_dir, suffix = corpus_paths("original")
        shapes = with_pool_columns(read_table(table_path))
        grasps = read_table(grasps_table("original"))
        label = f"render_views ({views} more per pose)"
        by_shape, results = render_corpus(
            shapes, grasps, mesh_dir, suffix, cfg, hand, params.seed, params.workers, label, stream="render-views"
        )
        parts_images, parts, skipped, _, _ = datapoints_index(shapes, by_shape, results, threshold)
        if parts:
            index, images = datapoints_table(parts), np.concatenate(parts_images)
    if index is None:  # no view asked, or none gave a datapoint: an empty corpus the views networks refuse
        index = pd.DataFrame({"shape_id": pd.Series(dtype="string"), "z": [], "label": [], "eps": []})
    with atomic_path(gqcnn_dir("views"), directory=True) as folder:
        write_grasp_images(folder, images, index, cfg.shard_rows)
        info = dataset_info("views", cfg, hand, threshold) | {"extra_views": views, "stream": "render-views"}
        (folder / "dataset.json").write_text(json.dumps(info, indent=2) + "\n")
        pd.DataFrame(skipped, columns=["shape_id", "reason"]).to_parquet(folder / "skipped.parquet", index=False)
    seconds = time.perf_counter() - start
    timing = {"seconds": round(seconds, 1), "datapoints": len(index), "extra_views": views}
    write_json(timing, timing_file("render", "views"))
    log.info("render_views: %d datapoints from %d extra view(s) per pose, %.1f s", len(index), views, seconds)


if __name__ == "__main__":
    from graspaug.pipeline.entry import stage_main

    stage_main(__spec__.name)
