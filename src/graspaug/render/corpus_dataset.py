"""A whole corpus's Dex-Net 2.0 dataset: render jobs, the datapoint index, its description,
metrics and example crops (the ``render`` stage's tables)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from graspaug.grasping.gripper import ParallelJawGripper
from graspaug.io.meshes import mesh_path
from graspaug.render.dataset import render_file
from graspaug.render.settings import RenderSettings


def with_pool_columns(shapes: pd.DataFrame) -> pd.DataFrame:
    """``shapes`` (a corpus table) with ``base_size`` and ``order`` (Int64) and ``pool`` (string)
    columns, all missing in a corpus of original shapes: the same column types for every corpus.
    Changes ``shapes`` in place and returns it."""
    for column in ("base_size", "pool", "order"):
        if column not in shapes:
            shapes[column] = None
    shapes["base_size"] = shapes["base_size"].astype("Int64")
    shapes["order"] = shapes["order"].astype("Int64")
    shapes["pool"] = shapes["pool"].astype("string")  # same column types for every corpus
    return shapes


def render_corpus(
    shapes: pd.DataFrame,
    grasps: pd.DataFrame,
    mesh_dir: Path,
    suffix: str,
    settings: RenderSettings,
    hand: ParallelJawGripper,
    seed: int,
    workers: int,
    label: str,
    stream: str = "render",
) -> tuple[dict[str, pd.DataFrame], list]:
    """Render every shape of ``shapes`` with its grasps, in parallel.

    Parameters
    ----------
    shapes : corpus table with ``shape_id``
    grasps : grasp table with ``shape_id``, ``center_x`` … ``center_z`` (m) and unit ``axis_x`` … ``axis_z``
    mesh_dir, suffix : the folder and file-name suffix of the shapes' meshes (:func:`graspaug.io.meshes.mesh_path`)
    settings, hand, seed : as :func:`graspaug.render.dataset.render_file` takes them
    workers, label : worker processes and progress label of :func:`graspaug.parallel.parallel_map`
    stream : the purpose of each shape's random stream (``render``; ``render-views``: other camera views of the
        same shapes, the ``views`` corpus)

    Returns
    -------
    (by_shape, results): shape id → its grasp rows (shapes without grasps absent), and per shape of
    ``shapes`` (ShapeDatapoints or None, reason), as :func:`graspaug.render.dataset.datapoints_index` takes them.
    """
    from graspaug.parallel import parallel_map

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
    results = parallel_map(lambda job: render_file(*job, settings, hand, seed, stream), jobs, workers, label)
    return by_shape, results


def datapoints_table(parts: list[pd.DataFrame]) -> pd.DataFrame:
    """The dataset's index: the per-shape index ``parts`` of :func:`graspaug.render.dataset.datapoints_index`
    concatenated, with ``base_size`` / ``order`` as Int64 and ``pool`` as string columns."""
    index = pd.concat(parts, ignore_index=True)
    for column in ("base_size", "order"):
        index[column] = index[column].astype("Int64")
    index["pool"] = index["pool"].astype("string")
    return index


def dataset_info(corpus: str, settings: RenderSettings, hand: ParallelJawGripper, threshold: float) -> dict:
    """The dataset's description: corpus name, camera intrinsics (px), crop and output sizes (px),
    the gripper's maximal opening ``hand.max_width`` (m) and the label rule with its robust ε ``threshold``."""
    camera = settings.intrinsics
    return {
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
        "label": f"collision_free and robust Ferrari-Canny eps_mean > {threshold}",
        "grasps_threshold": threshold,
    }


def render_summary(
    n_shapes: int, parts: list[pd.DataFrame], skipped: list[dict], index: pd.DataFrame, n_rays: int, n_poses: list[int]
) -> dict:
    """The ``render`` stage's metrics: shape and datapoint counts, means per shape, label /
    collision-free / success shares (rounded), counts by split and rays cast per datapoint.

    ``n_shapes``: shapes in the corpus; ``parts``, ``skipped``, ``n_rays``, ``n_poses``: as
    :func:`graspaug.render.dataset.datapoints_index` returns them; ``index``: :func:`datapoints_table`.
    """
    return {
        "n_shapes": n_shapes,
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


def render_headline(summary: dict) -> dict:
    """The stage's metrics from its :func:`render_summary`: ``shapes`` rendered, ``datapoints`` and the
    share of datapoints labelled positive (``positive``)."""
    return {
        "shapes": summary["shapes_rendered"],
        "datapoints": summary["n_datapoints"],
        "positive": summary["positive_share"],
    }


def example_crops(
    index: pd.DataFrame, n_examples: int, seed: int, factor: int
) -> tuple[np.ndarray, list[str], np.ndarray]:
    """Up to ``n_examples`` datapoints to show: half positives, the rest negatives, drawn with
    the generator ``[seed, len(index)]`` and each group in index order.

    Returns
    -------
    chosen : (n,) int — rows of ``index`` (and of the images), positives first
    titles : per row its label sign, shape id, robust ε, depth ``z`` (m) and "hit" if the approach collides
    jaw_half_widths : (n,) float — half the open jaws in output-crop px (``width_px`` / 2 / ``factor``)
    """
    rng = np.random.default_rng([seed, len(index)])
    half = n_examples // 2
    positives, negatives = np.flatnonzero(index.label.to_numpy()), np.flatnonzero(~index.label.to_numpy())
    take_pos = rng.choice(positives, min(len(positives), half), replace=False)
    take_neg = rng.choice(negatives, min(len(negatives), n_examples - len(take_pos)), replace=False)
    chosen = np.concatenate([np.sort(take_pos), np.sort(take_neg)])
    picked = index.iloc[chosen]
    titles = [
        f"{'+' if r.label else '-'} {r.shape_id}\nε={r.eps:.4f} z={r.z:.3f}" + ("" if r.collision_free else " hit")
        for r in picked.itertuples()
    ]
    return chosen, titles, picked.width_px.to_numpy() / 2 / factor
