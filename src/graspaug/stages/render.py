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
``label`` (= collision_free and success); ``metrics/render/<corpus>.json``;
``reports/render/<corpus>/examples.png``.
"""

from __future__ import annotations

import json
import logging
import time

import numpy as np
import pandas as pd

from graspaug.io.atomic import atomic_path
from graspaug.io.gqcnn import write_grasp_images
from graspaug.io.meshes import mesh_path
from graspaug.io.tables import read_table, write_json
from graspaug.params.base import params_model
from graspaug.params.grasps import GraspsParams
from graspaug.params.render import RenderParams
from graspaug.paths import gqcnn_dir, grasps_table, render_examples, render_metrics, timing_file
from graspaug.render.dataset import datapoints_index, render_file
from graspaug.stages import StageError, corpus_paths

log = logging.getLogger(__name__)

Params = params_model("The params the `render` stage reads.", render=RenderParams, grasps=GraspsParams)


def run(params: Params, corpus: str = "original") -> None:
    from graspaug.parallel import parallel_map
    from graspaug.plots import crop_grid

    files = corpus_paths(corpus)
    start = time.perf_counter()
    settings = cfg = params.render
    hand = params.grasps.gripper
    table_path, mesh_dir, suffix = files
    shapes = read_table(table_path)
    for column in ("base_size", "pool", "order"):
        if column not in shapes:
            shapes[column] = None
    shapes["base_size"] = shapes["base_size"].astype("Int64")
    shapes["order"] = shapes["order"].astype("Int64")
    shapes["pool"] = shapes["pool"].astype("string")  # same column types for every corpus
    grasps = read_table(grasps_table(corpus))
    by_shape = {shape_id: rows for shape_id, rows in grasps.groupby("shape_id", sort=False)}
    empty = grasps.iloc[:0]
    jobs = []
    for shape_id in shapes.shape_id:
        rows = by_shape.get(shape_id, empty)
        jobs.append(
            (
                mesh_path(mesh_dir.resolve(), shape_id, suffix),
                shape_id,
                rows[["center_x", "center_y", "center_z"]].to_numpy(),
                rows[["axis_x", "axis_y", "axis_z"]].to_numpy(),
            )
        )
    results = parallel_map(
        lambda job: render_file(*job, settings, hand, params.seed), jobs, params.workers, f"render ({corpus})"
    )

    images, parts, skipped, n_rays, n_poses = datapoints_index(shapes, by_shape, results, params.grasps.threshold)
    if not parts:
        raise StageError(
            f"render ({corpus}): no shape gave a datapoint; reasons: {sorted({s['reason'] for s in skipped})[:3]}"
        )
    index = pd.concat(parts, ignore_index=True)
    for column in ("base_size", "order"):
        index[column] = index[column].astype("Int64")
    index["pool"] = index["pool"].astype("string")
    images = np.concatenate(images)
    camera = settings.intrinsics
    dataset_info = {
        "corpus": corpus,
        "intrinsics": {
            "width": camera.width,
            "height": camera.height,
            "fx": camera.fx,
            "fy": camera.fy,
            "cx": camera.cx,
            "cy": camera.cy,
        },
        "crop_size": settings.crop.crop_size,
        "out_size": settings.crop.out_size,
        "gripper_max_width": hand.max_width,
        "label": f"collision_free and robust Ferrari-Canny eps_mean > {params.grasps.threshold}",
        "grasps_threshold": params.grasps.threshold,
    }
    with atomic_path(gqcnn_dir(corpus), directory=True) as folder:
        write_grasp_images(folder, images, index, cfg.shard_rows)
        (folder / "dataset.json").write_text(json.dumps(dataset_info, indent=2) + "\n")
        pd.DataFrame(skipped, columns=["shape_id", "reason"]).to_parquet(folder / "skipped.parquet", index=False)

    seconds = time.perf_counter() - start
    summary = {
        "n_shapes": len(shapes),
        "shapes_rendered": len(parts),
        "shapes_skipped": len(skipped),
        "n_datapoints": len(index),
        "datapoints_per_shape_mean": round(len(index) / len(parts), 1),
        "stable_poses_per_shape_mean": round(float(np.mean(n_poses)), 2),
        "positive_share": round(float(index.label.mean()), 4),
        "collision_free_share": round(float(index.collision_free.mean()), 4),
        "success_share": round(float(index.success.mean()), 4),
        "by_split": {
            split: {
                "datapoints": int(len(rows)),
                "positives": int(rows.label.sum()),
                "shapes": int(rows.shape_id.nunique()),
            }
            for split, rows in index.groupby("split")
        },
        "rays_per_datapoint": round(n_rays / len(index), 1),
    }
    write_json(summary, render_metrics(corpus))
    write_json(
        {"seconds": round(seconds, 1), "datapoints_per_second": round(len(index) / seconds, 1)},
        timing_file("render", corpus),
    )

    rng = np.random.default_rng([params.seed, len(index)])
    half = cfg.n_examples // 2
    positives, negatives = np.flatnonzero(index.label.to_numpy()), np.flatnonzero(~index.label.to_numpy())
    take_pos = rng.choice(positives, min(len(positives), half), replace=False)
    take_neg = rng.choice(negatives, min(len(negatives), cfg.n_examples - len(take_pos)), replace=False)
    chosen = np.concatenate([np.sort(take_pos), np.sort(take_neg)])
    picked = index.iloc[chosen]
    titles = [
        f"{'+' if r.label else '-'} {r.shape_id}\nε={r.eps:.4f} z={r.z:.3f}" + ("" if r.collision_free else " hit")
        for r in picked.itertuples()
    ]
    crop_grid(
        images[chosen],
        titles,
        picked.width_px.to_numpy() / 2 / settings.crop.factor,
        render_examples(corpus),
        f"render ({corpus}): positives (+) then negatives (-); red ticks: open jaws; 'hit': approach collides",
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
