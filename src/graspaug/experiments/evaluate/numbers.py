"""Each model's test AP on one test set with its 95% interval over objects, and the paired difference of every model
against the first: the same datapoints, the same bootstrap resamples of the objects (:mod:`graspaug.experiments.stats`).
Given the models as training seeds of networks, each network's mean AP and each network's paired difference to the
first with the verdict interval over seeds and objects (:func:`~graspaug.experiments.stats.nested_t_interval`).
"""

from __future__ import annotations

import numpy as np

from graspaug.experiments.stats import (
    ObjectBootstrap,
    contrast,
    nested_contrast,
    nested_t_interval,
    percentile_interval,
    weighted_average_precision,
)


def test_ap(
    labels: np.ndarray,
    object_ids: np.ndarray,
    probabilities: dict[str, np.ndarray],
    n_resamples: int,
    seed: int,
    seeds: int | None = None,
    replicates: str = "seeds",
) -> dict:
    """AP of every model and the paired difference of each against the first.

    Parameters
    ----------
    labels : (N,) bool — the datapoints' labels (collision free and robust ε above the threshold)
    object_ids : (N,) str — each datapoint's object, the bootstrap's clusters
    probabilities : model name → (N,) float — its P(success) of every datapoint, the first the reference
    n_resamples, seed : the object bootstrap's resamples and seed (the same resamples for every model)
    seeds : None, or S ≥ 2: the models, in order, are S training seeds of each network (the first S one network, the
        next S the next…; seed k of every network paired with seed k of the others). The count of models must be a
        multiple of S.
    replicates : what the S models of a network are replicates over: ``seeds`` (training seeds of one draw) or
        ``draws`` (one network of each of S draws of the data); the report says which its intervals cover.

    Returns
    -------
    ``{"models": name → contrast over objects (AP, 95% interval), "differences": "<name> − <first>" → contrast over
    objects, "datapoints", "positives", "objects"}``; an AP is None when no datapoint is positive, an interval None
    with one object (resampling one object gives its AP every time: no interval). With ``seeds``, also
    ``"networks"``: "<first model> (S seeds)" → its mean AP over the seeds as a contrast over ``draws`` (95%: t over
    the S seeds with the objects' bootstrap), and ``"network_differences"``: "<network> − <first network>" → the same
    for the paired difference.
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
    out = {
        "models": models,
        "differences": differences,
        "datapoints": int(len(labels)),
        "positives": int(labels.sum()),
        "objects": int(boot.n_objects),
    }
    return out if seeds is None else out | _networks(point, resampled, seeds, replicates) | {"replicates": replicates}


def _networks(point: dict[str, float | None], resampled: dict[str, np.ndarray], seeds: int, over: str) -> dict:
    """``networks`` and ``network_differences`` of :func:`test_ap`: the models in consecutive groups of ``seeds``."""
    names = list(point)
    if seeds < 2 or len(names) % seeds:
        raise ValueError(f"{len(names)} models are not networks of {seeds} seeds each (seeds ≥ 2, a whole multiple)")
    groups = [names[i : i + seeds] for i in range(0, len(names), seeds)]
    full = {g[0]: np.array([[np.nan if point[n] is None else point[n] for n in g]]) for g in groups}  # (1, S)
    boot = {g[0]: np.stack([resampled[n] for n in g])[None] for g in groups}  # (1, S, R)
    if over == "draws":  # networks of S draws, one seed each: (S, 1), so a verdict says it covers S draws
        full, boot = {k: v.T for k, v in full.items()}, {k: v.transpose(1, 0, 2) for k, v in boot.items()}
    label = {g[0]: f"{g[0]} ({seeds} {over})" for g in groups}
    first = groups[0][0]
    networks = {label[k]: nested_contrast(nested_t_interval(full[k], boot[k])) for k in full}
    differences = {
        f"{label[k]} − {label[first]}": nested_contrast(nested_t_interval(full[k] - full[first], boot[k] - boot[first]))
        for k in list(full)[1:]
    }
    return {"networks": networks, "network_differences": differences}


def _interval(resampled: np.ndarray, n_objects: int) -> tuple[float, float] | None:
    """The 95% percentile interval of (n_resamples,) ``resampled`` values; None over fewer than two objects."""
    return percentile_interval(resampled) if n_objects > 1 else None
