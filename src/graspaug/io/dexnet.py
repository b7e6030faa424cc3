"""Dex-Net 2.0's tensor dataset layout, so Berkeley's gqcnn tooling can read our data.

``<dir>/tensors/<field>_%05d.npz`` (key ``arr_0``, ``rows_per_file`` rows per file, the last
one shorter) for every field, plus ``<dir>/config.json`` in autolab_core's TensorDataset form
(``datapoints_per_file`` and per field ``dtype`` / ``height`` / ``width`` / ``channels``).
"""

from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np


def write_tensor_dataset(
    folder: str | os.PathLike, fields: dict[str, np.ndarray], rows_per_file: int = 1000, extra: dict | None = None
) -> int:
    """Write ``fields`` (name → array with N rows each) as a TensorDataset into ``folder`` (made
    if missing); returns the number of files per field. ``extra`` goes into config.json too."""
    sizes = {name: len(values) for name, values in fields.items()}
    if len(set(sizes.values())) > 1:
        raise ValueError(f"fields have different row counts: {sizes}")
    if rows_per_file < 1:
        raise ValueError(f"rows_per_file must be >= 1, got {rows_per_file}")
    folder = Path(folder)
    tensors = folder / "tensors"
    tensors.mkdir(parents=True, exist_ok=True)
    n = next(iter(sizes.values()), 0)
    n_files = 0
    for n_files, start in enumerate(range(0, n, rows_per_file), start=1):
        for name, values in fields.items():
            np.savez_compressed(tensors / f"{name}_{n_files - 1:05d}.npz", values[start : start + rows_per_file])
    config = {"datapoints_per_file": rows_per_file, "num_datapoints": n, "fields": {}}
    for name, values in fields.items():
        spec: dict[str, object] = {"dtype": str(values.dtype)}
        for key, size in zip(("height", "width", "channels"), values.shape[1:]):
            spec[key] = int(size)
        config["fields"][name] = spec
    config.update(extra or {})
    (folder / "config.json").write_text(json.dumps(config, indent=2) + "\n")
    return n_files


def read_tensor_field(folder: str | os.PathLike, name: str) -> np.ndarray:
    """All rows of one field of a TensorDataset folder, files concatenated in order."""
    files = sorted((Path(folder) / "tensors").glob(f"{name}_[0-9][0-9][0-9][0-9][0-9].npz"))
    if not files:
        raise FileNotFoundError(f"{folder}: no tensors/{name}_00000.npz")
    return np.concatenate([np.load(f)["arr_0"] for f in files])


def export_dexnet(
    source: str | os.PathLike, out: str | os.PathLike, rows_per_file: int = 1000, pool: str | None = None
) -> int:
    """Write the rendered dataset in folder ``source`` (``data/gqcnn/<corpus>``) in Dex-Net 2.0's
    tensor layout into ``out``; returns the number of datapoints.

    ``pool`` (a generated corpus ``gen_<B>`` only: ``targeted``, ``random``, ...) exports that pool's
    datapoints alone; None exports every pool, each datapoint's pool in the ``pool_labels`` field
    (indices into config.json's ``pools``). config.json of a generated corpus names the pool exported
    (``pool``: a name or ``all``). Raises :class:`~graspaug.errors.DataError` for a pool the corpus does not hold."""
    from graspaug.errors import DataError
    from graspaug.io.atomic import atomic_path
    from graspaug.io.gqcnn import GraspImages

    source = Path(source)
    if not (source / "index.parquet").exists():
        raise FileNotFoundError(
            f"{source}: no rendered dataset (run `dvc repro` or `graspaug render --corpus {source.name}` first)"
        )
    out = Path(out)
    if out.exists() and any(out.iterdir()):
        raise FileExistsError(f"{out} exists and is not empty; choose a new folder")
    data = GraspImages.open(source)
    info = json.loads((source / "dataset.json").read_text())
    index = data.index
    pools = sorted(index["pool"].dropna().unique()) if "pool" in index else []
    rows = None
    if pool is not None:
        if pool not in pools:
            held = f"its pools: {', '.join(pools)}" if pools else "it holds no pools (only generated corpora do)"
            raise DataError(f"--pool {pool}: not a pool of {source.name}; {held}")
        rows = np.flatnonzero((index["pool"] == pool).to_numpy(dtype=bool, na_value=False))
        index = index.iloc[rows].reset_index(drop=True)
    obj_ids, obj_labels = np.unique(index.shape_id.to_numpy(), return_inverse=True)
    pose_keys = index.shape_id + ":" + index.pose_id.astype(str)
    pose_ids, pose_labels = np.unique(pose_keys.to_numpy(), return_inverse=True)
    _, image_labels = np.unique((pose_keys + ":" + index.image_id.astype(str)).to_numpy(), return_inverse=True)
    cx, cy = info["intrinsics"]["cx"], info["intrinsics"]["cy"]
    hand_poses = np.stack(
        [
            index.center_v,
            index.center_u,
            index.z,
            index.angle,
            index.center_v - cy,
            index.center_u - cx,
            index.width_px,
        ],
        axis=1,
    )
    fields = {
        "depth_ims_tf_table": data.images(rows)[..., None],
        "hand_poses": hand_poses.astype(np.float32),
        # Dex-Net stores each metric times collision_free, and gqcnn labels by the metric alone
        "robust_ferrari_canny": (index.eps * index.collision_free).to_numpy(np.float32),
        "robust_ferrari_canny_raw": index.eps.to_numpy(np.float32),
        "collision_free": index.collision_free.to_numpy(np.uint8),
        "obj_labels": obj_labels.astype(np.uint32),
        "pose_labels": pose_labels.astype(np.uint32),
        "image_labels": image_labels.astype(np.uint32),
    }
    if pools and pool is None:  # every pool, mixed: say which each datapoint is
        fields["pool_labels"] = np.searchsorted(pools, index["pool"].to_numpy(dtype=object)).astype(np.uint8)
    named = {"pool": pool or "all", "pools": [pool] if pool else pools} if pools else {}
    extra = {
        "source": f"graspaug render ({source.name}" + (f", pool {named['pool']})" if pools else ")"),
        **named,
        "dataset": info,
        "obj_ids": obj_ids.tolist(),
        "pose_ids": pose_ids.tolist(),
        "hand_poses_columns": [
            "center_row",
            "center_col",
            "depth",
            "angle",
            "center_row_minus_cy",
            "center_col_minus_cx",
            "width_px",
        ],
        "label_rule": f"robust_ferrari_canny > {info['grasps_threshold']} (robust_ferrari_canny is 0 for colliding "
        "grasps, as in Dex-Net; robust_ferrari_canny_raw keeps the robust epsilon before that)",
    }
    with atomic_path(out, directory=True) as folder:
        write_tensor_dataset(folder, fields, rows_per_file, extra)
    return len(index)
