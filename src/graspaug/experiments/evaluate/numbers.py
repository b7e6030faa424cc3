"""Each model's test AP on one test set with its 95% interval over objects, and the paired difference of every model
against the first: the same datapoints, the same bootstrap resamples of the objects (:mod:`graspaug.experiments.stats`).
Given the models as training seeds of networks, each network's mean AP and each network's paired difference to the
first with the verdict interval over seeds and objects (:func:`~graspaug.experiments.stats.nested_t_interval`).
"""

from __future__ import annotations

import numpy as np
from tqdm import tqdm

from graspaug.experiments.stats import (
    DIFFERENCE_RANGE,
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
    arms: list[str] | None = None,
    pairs: list[str] | None = None,
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
    arms : with ``seeds``, each arm's name (e.g. ``none@50``, ``targeted@50``); default: its first model's name
    pairs : with ``seeds``, each replicate's name, k-th of every arm (e.g. ``d10 s0``); default ``replicate k``

    Returns
    -------
    ``{"models": name → contrast over objects (AP, 95% interval), "differences": "<name> − <first>" → contrast over
    objects (with ``seeds``: each model against the first arm's model of the same replicate, "<arm> − <first arm>
    (<replicate>)", the same draw and training seed), "datapoints", "positives", "objects"}``; an AP is None when no
    datapoint is positive, an interval None with one object (resampling one object gives its AP every time: no
    interval). With ``seeds``, also
    ``"networks"``: "<arm> (S seeds)" → its mean AP over the seeds as a contrast over ``draws`` (95%: t over
    the S seeds with the objects' bootstrap, clipped to AP's range [0, 1]), and ``"network_differences"``: "<arm> −
    <first arm>" → the same for the paired difference (clipped to [−1, 1]).
    """
    labels = np.asarray(labels, dtype=bool)
    if seeds is not None and (seeds < 2 or len(probabilities) % seeds):
        raise ValueError(f"{len(probabilities)} models are not networks of {seeds} seeds each (seeds ≥ 2, a multiple)")
    boot = ObjectBootstrap(object_ids, n_resamples, seed)
    point, resampled, models = {}, {}, {}
    bar = tqdm(probabilities.items(), desc=f"evaluate: AP, {n_resamples} resamples", unit="network", leave=False)
    for name, p in bar:
        ap = float(weighted_average_precision(labels, p, np.ones(len(labels))))  # the AP itself: every datapoint once
        point[name] = None if np.isnan(ap) else ap
        resampled[name] = boot.average_precision(labels, p)
        models[name] = contrast(point[name], "objects", objects=_interval(resampled[name], boot.n_objects))
    names = list(probabilities)
    if seeds is None:
        against = {name: (f"{name} − {names[0]}", names[0]) for name in names[1:]}
    else:
        arms = arms or names[::seeds]
        pairs = pairs or [f"replicate {k + 1}" for k in range(seeds)]
        against = {
            name: (f"{arms[i // seeds]} − {arms[0]} ({pairs[i % seeds]})", names[i % seeds])
            for i, name in enumerate(names)
            if i >= seeds
        }
    differences = {}
    for name, (label, first) in against.items():
        mean = None if point[name] is None or point[first] is None else point[name] - point[first]
        diff = resampled[name] - resampled[first]  # paired: the same resamples
        differences[label] = contrast(mean, "objects", objects=_interval(diff, boot.n_objects))
    out = {
        "models": models,
        "differences": differences,
        "datapoints": int(len(labels)),
        "positives": int(labels.sum()),
        "objects": int(boot.n_objects),
    }
    if seeds is None:
        return out
    return out | _networks(point, resampled, seeds, replicates, arms) | {"replicates": replicates}


def _networks(
    point: dict[str, float | None], resampled: dict[str, np.ndarray], seeds: int, over: str, arms: list[str] | None
) -> dict:
    """``networks`` and ``network_differences`` of :func:`test_ap`: the models in consecutive groups of ``seeds``,
    named ``arms`` (default: each group's first model)."""
    names = list(point)
    groups = [names[i : i + seeds] for i in range(0, len(names), seeds)]
    full = {g[0]: np.array([[np.nan if point[n] is None else point[n] for n in g]]) for g in groups}  # (1, S)
    boot = {g[0]: np.stack([resampled[n] for n in g])[None] for g in groups}  # (1, S, R)
    if over == "draws":  # networks of S draws, one seed each: (S, 1), so a verdict says it covers S draws
        full, boot = {k: v.T for k, v in full.items()}, {k: v.transpose(1, 0, 2) for k, v in boot.items()}
    label = {g[0]: f"{(arms or names[::seeds])[i]} ({seeds} {over})" for i, g in enumerate(groups)}
    first = groups[0][0]
    networks = {label[k]: _clipped(nested_t_interval(full[k], boot[k]), AP_RANGE) for k in full}
    differences = {
        f"{label[k]} − {label[first]}": _clipped(
            nested_t_interval(full[k] - full[first], boot[k] - boot[first]), DIFFERENCE_RANGE
        )
        for k in list(full)[1:]
    }
    return {"networks": networks, "network_differences": differences}


#: The range of an AP: a mean AP's interval is clipped to it.
AP_RANGE = (0.0, 1.0)


def _clipped(nested: dict, bounds: tuple[float, float]) -> dict:
    """A :func:`nested_t_interval` as a contrast, its ends clipped to ``bounds`` (the quantity's range): the t and
    normal half-widths are symmetric and can leave the range; clipping drops only values the quantity cannot take,
    so the interval covers the true value exactly as often as before. ``clipped``: whether an end was moved."""
    low, high = nested["low"], nested["high"]
    moved = low is not None and (low < bounds[0] or high > bounds[1])
    if moved:
        nested = nested | {"low": max(low, bounds[0]), "high": min(high, bounds[1])}
    return nested_contrast(nested, clipped=moved)


def _interval(resampled: np.ndarray, n_objects: int) -> tuple[float, float] | None:
    """The 95% percentile interval of (n_resamples,) ``resampled`` values; None over fewer than two objects."""
    return percentile_interval(resampled) if n_objects > 1 else None
