"""Parquet tables (pandas + pyarrow), written atomically."""

from __future__ import annotations

import os

import pandas as pd

from graspaug.io.atomic import atomic_path


def write_table(df: pd.DataFrame, path: str | os.PathLike) -> None:
    """Write ``df`` to a parquet file (no index)."""
    with atomic_path(path) as tmp:
        df.to_parquet(tmp, index=False)


def write_csv(df: pd.DataFrame, path: str | os.PathLike) -> None:
    """Write ``df`` as CSV (no index), e.g. the data behind a ``dvc plots`` plot."""
    with atomic_path(path) as tmp:
        df.to_csv(tmp, index=False)


def read_table(path: str | os.PathLike) -> pd.DataFrame:
    """Read a table written by :func:`write_table` (parquet) or :func:`write_csv` (a ``.csv`` path)."""
    return pd.read_csv(path) if str(path).endswith(".csv") else pd.read_parquet(path)


def write_json(obj: object, path: str | os.PathLike) -> None:
    """Write ``obj`` as indented JSON, e.g. a stage's metrics for ``dvc metrics``."""
    import json

    with atomic_path(path) as tmp:
        tmp.write_text(json.dumps(obj, indent=2) + "\n")


def write_json_files(records: dict[str, object], folder: str | os.PathLike) -> None:
    """Write each of ``records`` (name → object) as ``<name>.json`` in ``folder``, replacing the whole
    folder at once (no file of an earlier run stays), e.g. one metrics file per contrast."""
    import json

    with atomic_path(folder, directory=True) as tmp:
        for name, obj in records.items():
            (tmp / f"{name}.json").write_text(json.dumps(obj, indent=2) + "\n")
