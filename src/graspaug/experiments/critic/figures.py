"""What the critic study's figures draw: outlier curves over α and rows of example interpolations."""

from __future__ import annotations

import numpy as np
import pandas as pd

from graspaug.experiments.critic.numbers import MODEL_LABELS
from graspaug.geometry.clusters import largest_cluster

# (S,) the interpolation weights of the example pairs' figure
EXAMPLE_ALPHAS = np.linspace(0, 1, 7, dtype=np.float32)


def outlier_columns(summary: dict[str, dict[str, dict]], alphas, keys: list[str]) -> dict[str, list]:
    """The outlier table, one row per α (``alphas``, named ``keys`` in ``summary``) and one column per
    model and interval end: ``alpha``, ``<model>``, …, ``<model>_low``, ``<model>_high``, …
    ``summary``: model → α key → :func:`~graspaug.experiments.stats.mean_interval` dict (outlier %)."""
    columns = {m: [s[k]["mean"] for k in keys] for m, s in summary.items()}
    bounds = {
        f"{m}_{end}": [s[k][f"objects_{end}"] for k in keys] for m, s in summary.items() for end in ("low", "high")
    }
    return {"alpha": list(alphas), **columns, **bounds}


def interpolation_rows(sequences: dict[str, np.ndarray], labels: dict[str, str]) -> tuple[list[list[tuple]], list[str]]:
    """The cells of the interpolations figure: per example pair, one row per model of its decoded
    grids (A, R, R, R) bool with their largest cluster; and the row labels (``pair <p> <label>``)."""
    rows, row_labels = [], []
    n_examples = len(next(iter(sequences.values()))) if sequences else 0
    for p in range(n_examples):
        for name, label in labels.items():
            rows.append([(g, largest_cluster(g)) for g in sequences[name][p]])
            row_labels.append(f"pair {p + 1} {label}")
    return rows, row_labels


def outlier_lines(wide: pd.DataFrame) -> tuple[dict[str, np.ndarray], dict[str, tuple[np.ndarray, np.ndarray]]]:
    """What :func:`graspaug.plots.lines` draws of the :func:`outlier_columns` table ``wide`` (one row per α):
    per model label, its (A,) mean outlier % and its (low, high) interval ends, (A,) each."""
    series = {label: wide[m].to_numpy(dtype=float) for m, label in MODEL_LABELS.items()}
    intervals = {
        label: (wide[f"{m}_low"].to_numpy(dtype=float), wide[f"{m}_high"].to_numpy(dtype=float))
        for m, label in MODEL_LABELS.items()
    }
    return series, intervals


def example_rows(sequences: dict[str, np.ndarray]) -> tuple[list[list[tuple]], list[str], list[str]]:
    """What :func:`graspaug.plots.voxel_rows` draws of the example pairs' ``sequences`` (model → (E, S, R, R, R)
    bool, decoded at :data:`EXAMPLE_ALPHAS`): the :func:`interpolation_rows` cells and row labels (the models'
    short names: their label up to `` (``), and the column labels (``α=0.50``)."""
    rows, row_labels = interpolation_rows(sequences, {m: label.split(" (")[0] for m, label in MODEL_LABELS.items()})
    return rows, row_labels, [f"α={a:.2f}" for a in EXAMPLE_ALPHAS]
