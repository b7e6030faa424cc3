"""The critic study (paper Section IV-B) with uncertainty: outliers of decoded interpolations,
per model and α, with bootstrap intervals over pairs, and paired contrasts between models.

Every model decodes the *same* pairs at the same weights, so a contrast is a paired
difference: pair p's outlier % under model A minus under model B, averaged over pairs.
Intervals are percentile bootstraps that resample pairs (one set of resamples for every
model, so the contrasts stay paired).
"""
from __future__ import annotations

import numpy as np
import torch

from graspaug.experiments.stats import percentile_interval
from graspaug.geometry.clusters import outlier_percentage
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


def decoded_interpolations(ae: AutoEncoder, z: np.ndarray, pairs: np.ndarray, alphas: np.ndarray, threshold: float, device: torch.device) -> np.ndarray:
    """(P, A, R, R, R) bool: the pairs of latents ``z`` (N, d) interpolated at ``alphas`` (A,), decoded, thresholded."""
    probs = decode(ae, interpolate(z, pairs, alphas).reshape(-1, z.shape[1]), device)
    return (probs > threshold).reshape(len(pairs), len(alphas), *probs.shape[1:])


def outlier_table(decoded: np.ndarray) -> np.ndarray:
    """(P, A) outlier % of every decoded grid (P, A, R, R, R); NaN for an empty grid."""
    flat = decoded.reshape(-1, *decoded.shape[2:])
    return np.array([outlier_percentage(g) for g in flat]).reshape(decoded.shape[:2])


def pair_resamples(n_pairs: int, n_resamples: int, rng: np.random.Generator) -> np.ndarray:
    """(n_resamples, P) pair indices drawn with replacement: one bootstrap resample per row."""
    return rng.integers(0, n_pairs, size=(n_resamples, n_pairs))


def _mean_with_interval(values: np.ndarray, resamples: np.ndarray, level: float) -> dict[str, float | None]:
    """Mean of ``values`` (P,) over finite entries and its bootstrap ``level`` interval over pairs."""
    finite = np.isfinite(values)
    if not finite.any():
        return {"mean": None, "ci_low": None, "ci_high": None}
    drawn = values[resamples]  # (n_resamples, P)
    counts = np.isfinite(drawn).sum(axis=1)
    sums = np.where(np.isfinite(drawn), drawn, 0.0).sum(axis=1)
    boot = np.divide(sums, counts, out=np.full(len(drawn), np.nan), where=counts > 0)  # NaNs left out
    low, high = percentile_interval(boot, level)
    return {"mean": float(np.mean(values[finite])), "ci_low": low, "ci_high": high}


def summarize(pct: np.ndarray, resamples: np.ndarray, level: float = 0.95) -> list[dict[str, float | None]]:
    """Per α (column of ``pct`` (P, A)): mean outlier % over pairs with its bootstrap interval."""
    return [_mean_with_interval(pct[:, i], resamples, level) for i in range(pct.shape[1])]


def paired_contrast(pct_a: np.ndarray, pct_b: np.ndarray, resamples: np.ndarray, level: float = 0.95) -> list[dict[str, float | None]]:
    """Per α: mean over pairs of ``pct_a − pct_b`` (both (P, A), same pairs) with its bootstrap
    interval; a pair empty under either model is left out."""
    diff = pct_a - pct_b  # NaN where either is NaN
    return [_mean_with_interval(diff[:, i], resamples, level) for i in range(diff.shape[1])]
