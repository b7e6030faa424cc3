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


def write_tensor_dataset(folder: str | os.PathLike, fields: dict[str, np.ndarray], rows_per_file: int = 1000, extra: dict | None = None) -> int:
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
