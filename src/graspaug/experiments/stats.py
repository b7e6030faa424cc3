"""Interval estimates for paired experiments: t-intervals over seeds and bootstrap intervals
that resample test *objects* (every datapoint of a drawn object comes along).

Average Precision here is sklearn's (step-wise, no interpolation): the mean over positives of
the precision at their rank, with datapoint weights for the bootstrap.
"""
from __future__ import annotations

import numpy as np
from scipy import stats


def t_interval(values, level: float = 0.95) -> dict:
    """Mean and two-sided ``level`` t-interval of ``values`` (one per seed); the interval is
    None for fewer than two values."""
    x = np.asarray([v for v in values if v is not None and np.isfinite(v)], dtype=float)
    n = len(x)
    if n == 0:
        return {"mean": None, "ci_low": None, "ci_high": None, "n_seeds": 0}
    mean = float(x.mean())
    if n < 2:
        return {"mean": mean, "ci_low": None, "ci_high": None, "n_seeds": 1}
    half = float(stats.t.ppf(0.5 + level / 2, n - 1) * x.std(ddof=1) / np.sqrt(n))
    return {"mean": mean, "ci_low": mean - half, "ci_high": mean + half, "n_seeds": n}


class ObjectBootstrap:
    """Resamples of the test objects: ``weights`` (n_resamples, n_datapoints), each row the
    number of times each datapoint's object was drawn (objects with replacement, as many as
    there are)."""

    def __init__(self, object_ids: np.ndarray, n_resamples: int, seed: int) -> None:
        objects, self.object_index = np.unique(np.asarray(object_ids), return_inverse=True)
        rng = np.random.default_rng(seed)
        draws = rng.integers(0, len(objects), size=(n_resamples, len(objects)))
        counts = np.zeros((n_resamples, len(objects)), dtype=np.float32)
        np.add.at(counts, (np.arange(n_resamples)[:, None], draws), 1.0)
        self.object_counts = counts
        self.n_objects = len(objects)

    def average_precision(self, labels: np.ndarray, scores: np.ndarray) -> np.ndarray:
        """AP of ``scores`` under every resample (n_resamples,)."""
        order = np.argsort(-np.asarray(scores), kind="stable")
        y = np.asarray(labels, dtype=np.float32)[order]
        w = self.object_counts[:, self.object_index[order]]
        return weighted_average_precision(y, w)


def weighted_average_precision(labels_sorted: np.ndarray, weights: np.ndarray) -> np.ndarray:
    """AP of datapoints already sorted by descending score, with weights (..., N): the
    weighted mean over positives of the precision at their rank."""
    tp = np.cumsum(weights * labels_sorted, axis=-1)
    seen = np.cumsum(weights, axis=-1)
    precision = np.divide(tp, seen, out=np.zeros_like(tp), where=seen > 0)
    positives = tp[..., -1]
    return np.divide((precision * weights * labels_sorted).sum(axis=-1), positives, out=np.full_like(positives, np.nan), where=positives > 0)


def percentile_interval(samples: np.ndarray, level: float = 0.95) -> tuple[float | None, float | None]:
    """Two-sided percentile interval of bootstrap ``samples`` (NaNs left out)."""
    x = np.asarray(samples, dtype=float)
    x = x[np.isfinite(x)]
    if len(x) == 0:
        return None, None
    low, high = np.quantile(x, [0.5 - level / 2, 0.5 + level / 2])
    return float(low), float(high)
