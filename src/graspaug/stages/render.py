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
from pathlib import Path

import numpy as np
import pandas as pd

from graspaug.config import Params, RenderParams
from graspaug.io.atomic import atomic_path
from graspaug.io.dexnet import write_tensor_dataset
from graspaug.io.gqcnn import GraspImages, write_grasp_images
from graspaug.io.meshes import mesh_path, read_mesh
from graspaug.io.tables import read_table, write_json
from graspaug.paths import gqcnn_dir, grasps_table, render_examples, render_metrics
from graspaug.render.camera import Intrinsics, ViewpointRanges
from graspaug.render.crops import CropGeometry
from graspaug.render.dataset import RenderSettings, ShapeDatapoints, render_shape
from graspaug.rng import shape_rng
from graspaug.stages import StageError, corpus_paths
from graspaug.stages.grasps import gripper

log = logging.getLogger(__name__)

SHAPE_COLUMNS = ("shape_id", "origin", "split", "base_size", "pool", "order")


def render_settings(cfg: RenderParams) -> RenderSettings:
    return RenderSettings(
        max_poses=cfg.max_poses, min_pose_probability=cfg.min_pose_probability, images_per_pose=cfg.images_per_pose,
        max_grasps_per_image=cfg.max_grasps_per_image, axis_tolerance_deg=cfg.axis_tolerance_deg, approach_distance=cfg.approach_distance,
        viewpoints=ViewpointRanges(distance=tuple(cfg.camera_distance), tilt_deg=tuple(cfg.camera_tilt_deg), object_offset=cfg.object_offset),
        intrinsics=Intrinsics(width=cfg.image_width, height=cfg.image_height, fx=cfg.focal_length, fy=cfg.focal_length,
                              cx=(cfg.image_width - 1) / 2, cy=(cfg.image_height - 1) / 2),
        crop=CropGeometry(crop_size=cfg.crop_size, out_size=cfg.out_size),
    )


def render_one(path: Path, shape_id: str, centers: np.ndarray, axes: np.ndarray, settings: RenderSettings, hand, seed: int) -> tuple[ShapeDatapoints | None, str | None]:
    """One shape's datapoints, or None and why there are none."""
    if len(centers) == 0:
        return None, "the shape has no grasps"
    try:
        mesh = read_mesh(path)
    except Exception as exc:  # a broken file is skipped with its reason, not fatal
        return None, f"mesh could not be read: {exc}"
    try:
        data = render_shape(mesh, centers, axes, hand, settings, shape_rng(seed, shape_id, "render"))
    except Exception as exc:  # a degenerate mesh (no hull, no volume) is skipped with its reason
        return None, f"rendering failed: {type(exc).__name__}: {exc}"
    if len(data) == 0:
        return None, (f"none of its {len(centers)} grasps has its jaw axis within {settings.axis_tolerance_deg} deg of the table "
                      f"in its {data.n_poses} stable poses")
    return data, None


def run(params: Params, corpus: str = "original") -> None:
    from graspaug.parallel import parallel_map
    from graspaug.plots import crop_grid

    files = corpus_paths(corpus)
    start = time.perf_counter()
    cfg = params.render
    settings = render_settings(cfg)
    hand = gripper(params.grasps)
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
        jobs.append((mesh_path(mesh_dir.resolve(), shape_id, suffix), shape_id, rows[["center_x", "center_y", "center_z"]].to_numpy(),
                     rows[["axis_x", "axis_y", "axis_z"]].to_numpy()))
    results = parallel_map(lambda job: render_one(*job, settings, hand, params.seed), jobs, params.workers, f"render ({corpus})")

    images, parts, skipped, n_rays, n_poses = [], [], [], 0, []
    for shape, (data, reason) in zip(shapes.itertuples(index=False), results):
        if data is None:
            skipped.append({"shape_id": shape.shape_id, "reason": reason})
            log.warning("render: %s has no datapoints: %s", shape.shape_id, reason)
            continue
        rows = by_shape[shape.shape_id].iloc[data.columns["grasp_index"]]
        part = pd.DataFrame({name: [getattr(shape, name)] * len(data) for name in SHAPE_COLUMNS})
        part["grasp_id"] = rows["grasp_id"].to_numpy()
        for name, values in data.columns.items():
            if name != "grasp_index":
                part[name] = values
        part["eps"] = rows["eps_mean"].to_numpy()
        part["success"] = part["eps"] > params.grasps.threshold
        part["label"] = part["collision_free"] & part["success"]
        parts.append(part)
        images.append(data.images)
        n_rays += data.n_rays
        n_poses.append(data.n_poses)
    if not parts:
        raise StageError(f"render ({corpus}): no shape gave a datapoint; reasons: {sorted({s['reason'] for s in skipped})[:3]}")
    index = pd.concat(parts, ignore_index=True)
    for column in ("base_size", "order"):
        index[column] = index[column].astype("Int64")
    index["pool"] = index["pool"].astype("string")
    images = np.concatenate(images)
    camera = settings.intrinsics
    dataset_info = {
        "corpus": corpus, "intrinsics": {"width": camera.width, "height": camera.height, "fx": camera.fx, "fy": camera.fy, "cx": camera.cx, "cy": camera.cy},
        "crop_size": settings.crop.crop_size, "out_size": settings.crop.out_size, "gripper_max_width": hand.max_width,
        "label": f"collision_free and robust Ferrari-Canny eps_mean > {params.grasps.threshold}", "grasps_threshold": params.grasps.threshold,
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
        "by_split": {split: {"datapoints": int(len(rows)), "positives": int(rows.label.sum()), "shapes": int(rows.shape_id.nunique())}
                     for split, rows in index.groupby("split")},
        "rays_per_datapoint": round(n_rays / len(index), 1),
        "seconds": round(seconds, 1),
        "datapoints_per_second": round(len(index) / seconds, 1),
    }
    write_json(summary, render_metrics(corpus))

    rng = np.random.default_rng([params.seed, len(index)])
    half = cfg.n_examples // 2
    positives, negatives = np.flatnonzero(index.label.to_numpy()), np.flatnonzero(~index.label.to_numpy())
    take_pos = rng.choice(positives, min(len(positives), half), replace=False)
    take_neg = rng.choice(negatives, min(len(negatives), cfg.n_examples - len(take_pos)), replace=False)
    chosen = np.concatenate([np.sort(take_pos), np.sort(take_neg)])
    picked = index.iloc[chosen]
    titles = [f"{'+' if r.label else '-'} {r.shape_id}\nε={r.eps:.4f} z={r.z:.3f}" + ("" if r.collision_free else " hit") for r in picked.itertuples()]
    crop_grid(images[chosen], titles, picked.width_px.to_numpy() / 2 / settings.crop.factor, render_examples(corpus),
              f"render ({corpus}): positives (+) then negatives (-); red ticks: open jaws; 'hit': approach collides")
    log.info("render (%s): %d datapoints from %d shapes (%d skipped), %.1f%% positive (%.1f%% collision free), %.1f s", corpus, len(index),
             len(parts), len(skipped), 100 * summary["positive_share"], 100 * summary["collision_free_share"], seconds)


def export_dexnet(corpus: str, out: str | Path, rows_per_file: int = 1000) -> int:
    """Write the rendered dataset of ``corpus`` in Dex-Net 2.0's tensor layout into ``out``;
    returns the number of datapoints."""
    source = gqcnn_dir(corpus)
    if not (source / "index.parquet").exists():
        raise StageError(f"{source}: no rendered dataset (run `dvc repro` or `graspaug render --corpus {corpus}` first)")
    out = Path(out)
    if out.exists() and any(out.iterdir()):
        raise FileExistsError(f"{out} exists and is not empty; choose a new folder")
    data = GraspImages.open(source)
    info = json.loads((source / "dataset.json").read_text())
    index = data.index
    obj_ids, obj_labels = np.unique(index.shape_id.to_numpy(), return_inverse=True)
    pose_keys = index.shape_id + ":" + index.pose_id.astype(str)
    pose_ids, pose_labels = np.unique(pose_keys.to_numpy(), return_inverse=True)
    _, image_labels = np.unique((pose_keys + ":" + index.image_id.astype(str)).to_numpy(), return_inverse=True)
    cx, cy = info["intrinsics"]["cx"], info["intrinsics"]["cy"]
    hand_poses = np.stack([index.center_v, index.center_u, index.z, index.angle, index.center_v - cy, index.center_u - cx, index.width_px], axis=1)
    fields = {
        "depth_ims_tf_table": data.images()[..., None],
        "hand_poses": hand_poses.astype(np.float32),
        # Dex-Net stores each metric times collision_free, and gqcnn labels by the metric alone
        "robust_ferrari_canny": (index.eps * index.collision_free).to_numpy(np.float32),
        "robust_ferrari_canny_raw": index.eps.to_numpy(np.float32),
        "collision_free": index.collision_free.to_numpy(np.uint8),
        "obj_labels": obj_labels.astype(np.uint32),
        "pose_labels": pose_labels.astype(np.uint32),
        "image_labels": image_labels.astype(np.uint32),
    }
    extra = {"source": f"graspaug render ({corpus})", "dataset": info, "obj_ids": obj_ids.tolist(), "pose_ids": pose_ids.tolist(),
             "hand_poses_columns": ["center_row", "center_col", "depth", "angle", "center_row_minus_cy", "center_col_minus_cx", "width_px"],
             "label_rule": f"robust_ferrari_canny > {info['grasps_threshold']} (robust_ferrari_canny is 0 for colliding grasps, as in Dex-Net; "
                           "robust_ferrari_canny_raw keeps the robust epsilon before that)"}
    with atomic_path(out, directory=True) as folder:
        write_tensor_dataset(folder, fields, rows_per_file, extra)
    return len(index)
