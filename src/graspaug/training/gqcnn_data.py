"""The GQ-CNN experiment's datasets: training sets (base shapes + a share of a generated pool),
the validation views held out of them, and the test set, read from the rendered corpora.

Datapoints are :class:`~graspaug.training.gqcnn.GraspArrays`. The training set of base size B,
ratio R and pool P is the datapoints of the B base shapes (``data/generated/B/base.parquet``)
in ``data/gqcnn/original`` plus those of the first round(R × B) shapes of pool P in
``data/gqcnn/gen_B``; the test set is every test-split datapoint of ``data/gqcnn/original``.
"""
from __future__ import annotations

import zlib

import numpy as np

from graspaug.generation import ratio_count
from graspaug.io.gqcnn import GraspImages
from graspaug.io.tables import read_table
from graspaug.paths import base_set_table, gqcnn_dir
from graspaug.training.gqcnn import GraspArrays

POOLS = ("targeted", "random")


def _arrays(data: GraspImages, rows: np.ndarray) -> GraspArrays:
    return GraspArrays(data.images(rows), data.read("z", rows), data.read("labels", rows))


def training_set(base_size: int, ratio: float, pool: str) -> tuple[GraspArrays, np.ndarray, dict]:
    """The datapoints of the base shapes and of the first round(R·B) shapes of the pool, their
    view keys (for the validation split) and counts."""
    base = set(read_table(base_set_table(base_size)).shape_id)
    original = GraspImages.open(gqcnn_dir("original"))
    rows = np.flatnonzero(original.index.shape_id.isin(base).to_numpy())
    parts = [_arrays(original, rows)]
    keys = [("o:" + original.index.shape_id.iloc[rows] + ":" + original.index.image_id.iloc[rows].astype(str)).to_numpy()]
    n_generated, generated_shapes = ratio_count(ratio, base_size), 0
    if n_generated:
        generated = GraspImages.open(gqcnn_dir(f"gen_{base_size}"))
        index = generated.index
        gen_rows = np.flatnonzero(((index.pool == pool) & (index.order < n_generated)).to_numpy())
        parts.append(_arrays(generated, gen_rows))
        keys.append(("g:" + index.shape_id.iloc[gen_rows] + ":" + index.image_id.iloc[gen_rows].astype(str)).to_numpy())
        generated_shapes = int(index.shape_id.iloc[gen_rows].nunique())
    data = GraspArrays(*(np.concatenate([getattr(p, f) for p in parts]) for f in ("images", "z", "labels")))
    info = {"base_shapes": int(original.index.shape_id.iloc[rows].nunique()), "generated_shapes_asked": n_generated,
            "generated_shapes": generated_shapes, "datapoints": len(data), "positive_share": round(float(data.labels.mean()), 4) if len(data) else None}
    return data, np.concatenate(keys), info


def held_out_views(keys: np.ndarray, fraction: float, *seeds: int) -> np.ndarray:
    """(N,) bool: datapoints whose view (key) is held out for validation. Decided per view by a
    hash of the seeds and the key, so a base shape's view is held out (or not) alike for every
    ratio and pool: variants differ only by the generated shapes they add."""
    prefix = ":".join(map(str, seeds)) + ":"
    unique, inverse = np.unique(keys, return_inverse=True)
    chosen = np.array([zlib.crc32((prefix + key).encode()) / 2**32 < fraction for key in unique], dtype=bool)
    return chosen[inverse] if len(unique) else np.zeros(len(keys), dtype=bool)


def test_set() -> tuple[GraspArrays, np.ndarray]:
    """Every test-split datapoint of the original corpus and its row in the index."""
    original = GraspImages.open(gqcnn_dir("original"))
    rows = np.flatnonzero((original.index.split == "test").to_numpy())
    return _arrays(original, rows), rows
