"""The GQ-CNN dataset folder: depth crops in ``.npy`` shards plus one parquet index.

Layout of ``data/gqcnn/<corpus>/``:

- ``images_%05d.npy`` (n, out, out) float32: depth crops (m), ``shard_rows`` per shard;
- ``z_%05d.npy`` (n,) float32: gripper depth (m); ``labels_%05d.npy`` (n,) uint8: 1 = positive;
  ``eps_%05d.npy`` (n,) float32: robust Ferrari-Canny ε of the grasp;
- ``index.parquet``: one row per datapoint in shard order (``shard``, ``row`` within it, and
  the columns the render stage documents);
- ``skipped.parquet``: shapes without datapoints and why.

Shards open memory-mapped (:meth:`GraspImages.images`), so a trainer reads only what it uses.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

ARRAYS = {"images": np.float32, "z": np.float32, "labels": np.uint8, "eps": np.float32}


def shard_name(field: str, shard: int) -> str:
    return f"{field}_{shard:05d}.npy"


def write_grasp_images(folder: str | os.PathLike, images: np.ndarray, index: pd.DataFrame, shard_rows: int) -> None:
    """Write ``images`` (N, out, out) and ``index`` (N rows with ``z``, ``label``, ``eps``) into
    ``folder`` (which must exist; the caller makes it atomic). Adds ``shard`` and ``row``."""
    folder = Path(folder)
    if len(images) != len(index):
        raise ValueError(f"{len(images)} images but {len(index)} index rows")
    index = index.reset_index(drop=True)
    position = np.arange(len(index))
    index.insert(0, "row", position % shard_rows)
    index.insert(0, "shard", position // shard_rows)
    columns = {
        "images": images,
        "z": index["z"].to_numpy(),
        "labels": index["label"].to_numpy(),
        "eps": index["eps"].to_numpy(),
    }
    for shard, start in enumerate(range(0, len(index), shard_rows)):
        for field, dtype in ARRAYS.items():
            np.save(
                folder / shard_name(field, shard),
                np.ascontiguousarray(columns[field][start : start + shard_rows], dtype=dtype),
            )
    index.to_parquet(folder / "index.parquet", index=False)


@dataclass
class GraspImages:
    """A GQ-CNN dataset folder opened for reading: ``index`` (DataFrame) and memory-mapped shards."""

    folder: Path
    index: pd.DataFrame

    @classmethod
    def open(cls, folder: str | os.PathLike) -> GraspImages:
        folder = Path(folder)
        if not (folder / "index.parquet").exists():
            raise FileNotFoundError(f"{folder}: no index.parquet (run the render stage first)")
        return cls(folder=folder, index=pd.read_parquet(folder / "index.parquet"))

    def __len__(self) -> int:
        return len(self.index)

    def shard(self, field: str, shard: int) -> np.ndarray:
        """One shard of ``field`` (images, z, labels, eps), memory-mapped."""
        return np.load(self.folder / shard_name(field, shard), mmap_mode="r")

    def read(self, field: str, rows: np.ndarray | None = None) -> np.ndarray:
        """``field`` for dataset rows ``rows`` (positions in ``index``; default all), in that order."""
        rows = np.arange(len(self.index)) if rows is None else np.asarray(rows, dtype=int)
        shards = self.index["shard"].to_numpy()[rows]
        within = self.index["row"].to_numpy()[rows]
        sample = self.shard(field, 0) if len(self.index) else np.zeros((0,), ARRAYS[field])
        out = np.empty((len(rows), *sample.shape[1:]), dtype=ARRAYS[field])
        for shard in np.unique(shards):
            take = shards == shard
            out[take] = self.shard(field, int(shard))[within[take]]
        return out

    def images(self, rows: np.ndarray | None = None) -> np.ndarray:
        """Depth crops (n, out, out) float32 for ``rows``."""
        return self.read("images", rows)


def append_grasp_images(
    folder: str | os.PathLike, previous: str | os.PathLike | None, images: np.ndarray, index: pd.DataFrame, shard_rows
) -> int:
    """Write into ``folder`` the datapoints of the dataset folder ``previous`` (None: none) followed by ``images``
    and ``index`` (as :func:`write_grasp_images` takes them); returns how many there are in all."""
    data = GraspImages.open(previous) if previous is not None else None
    if data is not None and len(data):
        images = np.concatenate([data.images(), images])
        index = pd.concat([data.index.drop(columns=["shard", "row"]), index], ignore_index=True)
    write_grasp_images(folder, images, index, shard_rows)
    return len(index)
