"""Each model's test AP on one test set with its 95% interval over objects, and the paired difference of every model
against the first: the same datapoints, the same bootstrap resamples of the objects (:mod:`graspaug.experiments.stats`).
"""

from __future__ import annotations

import numpy as np

from graspaug.experiments.stats import ObjectBootstrap, contrast, percentile_interval, weighted_average_precision


def test_ap(
    labels: np.ndarray, object_ids: np.ndarray, probabilities: dict[str, np.ndarray], n_resamples: int, seed: int
) -> dict:
    """AP of every model and the paired difference of each against the first.

    Parameters
    ----------
    labels : (N,) bool — the datapoints' labels (collision free and robust ε above the threshold)
    object_ids : (N,) str — each datapoint's object, the bootstrap's clusters
    probabilities : model name → (N,) float — its P(success) of every datapoint, the first the reference
    n_resamples, seed : the object bootstrap's resamples and seed (the same resamples for every model)

    Returns
    -------
    ``{"models": name → contrast over objects (AP, 95% interval), "differences": "<name> − <first>" → contrast over
    objects, "datapoints", "positives", "objects"}``; an AP is None when no datapoint is positive, an interval None
    with one object (resampling one object gives its AP every time: no interval).
    """
    labels = np.asarray(labels, dtype=bool)
    boot = ObjectBootstrap(object_ids, n_resamples, seed)
    point, resampled, models = {}, {}, {}
    for name, p in probabilities.items():
        ap = float(weighted_average_precision(labels, p, np.ones(len(labels))))  # the AP itself: every datapoint once
        point[name] = None if np.isnan(ap) else ap
        resampled[name] = boot.average_precision(labels, p)
        models[name] = contrast(point[name], "objects", objects=_interval(resampled[name], boot.n_objects))
    first = next(iter(probabilities))
    differences = {}
    for name in list(probabilities)[1:]:
        mean = None if point[name] is None or point[first] is None else point[name] - point[first]
        diff = resampled[name] - resampled[first]  # paired: the same resamples
        differences[f"{name} − {first}"] = contrast(mean, "objects", objects=_interval(diff, boot.n_objects))
    return {
        "models": models,
        "differences": differences,
        "datapoints": int(len(labels)),
        "positives": int(labels.sum()),
        "objects": int(boot.n_objects),
    }


def _interval(resampled: np.ndarray, n_objects: int) -> tuple[float, float] | None:
    """The 95% percentile interval of (n_resamples,) ``resampled`` values; None over fewer than two objects."""
    return percentile_interval(resampled) if n_objects > 1 else None
