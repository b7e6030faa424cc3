"""The critic study (paper Section IV-B) with uncertainty: outliers of decoded interpolations,
per model and α, with bootstrap intervals over pairs, and paired contrasts between models.

Every model decodes the *same* pairs at the same weights, so a contrast is a paired
difference: pair p's outlier % under model A minus under model B, averaged over pairs.
Intervals are percentile bootstraps that resample pairs (one
:class:`~graspaug.experiments.stats.PairBootstrap` for every model, so the contrasts stay paired).
"""

from __future__ import annotations

import numpy as np
import torch

from graspaug.experiments.stats import PairBootstrap, mean_interval, paired_contrast
from graspaug.geometry.clusters import largest_cluster, outlier_percentage
from graspaug.nets.ae_critic import AutoEncoder
from graspaug.training.autoencoder import decode


def random_pairs(n: int, n_shapes: int, n_pairs: int, rng: np.random.Generator) -> np.ndarray:
    """(P, 2) index pairs: ``n_shapes`` of ``n`` drawn at random, paired off at random, first ``n_pairs``."""
    chosen = rng.choice(n, size=min(n, n_shapes), replace=False)
    pairs = rng.permutation(chosen)[: 2 * (len(chosen) // 2)].reshape(-1, 2)
    return pairs[:n_pairs]


def interpolate(z: np.ndarray, pairs: np.ndarray, alphas: np.ndarray) -> np.ndarray:
    """(P, A, d) latents ``(1 − α) z_a + α z_b`` for every pair and weight."""
    a, b = z[pairs[:, 0]][:, None], z[pairs[:, 1]][:, None]
    return (1 - alphas[None, :, None]) * a + alphas[None, :, None] * b


def decoded_interpolations(
    ae: AutoEncoder, z: np.ndarray, pairs: np.ndarray, alphas: np.ndarray, threshold: float, device: torch.device
) -> np.ndarray:
    """(P, A, R, R, R) bool: the pairs of latents ``z`` (N, d) interpolated at ``alphas`` (A,), decoded, thresholded."""
    probs = decode(ae, interpolate(z, pairs, alphas).reshape(-1, z.shape[1]), device)
    return (probs > threshold).reshape(len(pairs), len(alphas), *probs.shape[1:])


def outlier_table(decoded: np.ndarray) -> np.ndarray:
    """(P, A) outlier % of every decoded grid (P, A, R, R, R); NaN for an empty grid."""
    flat = decoded.reshape(-1, *decoded.shape[2:])
    return np.array([outlier_percentage(g) for g in flat]).reshape(decoded.shape[:2])


def summarize(pct: np.ndarray, boot: PairBootstrap, level: float = 0.95) -> list[dict[str, float | None]]:
    """Per α (column of ``pct`` (P, A), outlier %): mean outlier % over the pairs with a grid
    and its bootstrap ``level`` interval over pairs."""
    return [mean_interval(pct[:, i], boot, level) for i in range(pct.shape[1])]


def outlier_contrast(
    pct_a: np.ndarray, pct_b: np.ndarray, boot: PairBootstrap, level: float = 0.95
) -> list[dict[str, float | None]]:
    """Per α: mean over pairs of ``pct_a − pct_b`` (both (P, A) outlier %, the same pairs) with its
    bootstrap interval; a pair empty under either model is left out."""
    return [paired_contrast(pct_a[:, i], pct_b[:, i], boot, level) for i in range(pct_a.shape[1])]


def outlier_columns(summary: dict[str, dict[str, dict]], alphas, keys: list[str]) -> dict[str, list]:
    """The outlier table, one row per α (``alphas``, named ``keys`` in ``summary``) and one column per
    model and interval end: ``alpha``, ``<model>``, …, ``<model>_low``, ``<model>_high``, …
    ``summary``: model → α key → :func:`~graspaug.experiments.stats.mean_interval` dict (outlier %)."""
    columns = {m: [s[k]["mean"] for k in keys] for m, s in summary.items()}
    bounds = {f"{m}_{end}": [s[k][f"ci_{end}"] for k in keys] for m, s in summary.items() for end in ("low", "high")}
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
