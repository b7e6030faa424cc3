"""The statistics of the three experiments (GQ-CNN AP, critic study, simulated trials).

* :func:`t_interval`: mean and t-interval over training seeds (the replicates);
* :class:`ObjectBootstrap`: the cluster bootstrap. Each resample draws the clusters (test
  objects; the critic study's interpolation pairs: :class:`PairBootstrap`) with replacement, as
  many as there are, and every datapoint of a drawn cluster comes along;
* :func:`percentile_interval`, :func:`mean_interval`, :func:`paired_contrast`: the mean of values
  (of paired differences) with its percentile bootstrap interval;
* :func:`weighted_average_precision`: Average Precision as sklearn's (step-wise, no
  interpolation, tied scores one threshold), with datapoint weights for the bootstrap;
  :func:`weighted_roc_auc`: ROC AUC as sklearn's (ties count half), with datapoint weights;
* :func:`nested_t_interval`: the one interval every verdict reads, over data draws, training seeds and test
  objects (the replicates' t half-width and the object bootstrap's normal one in quadrature, :func:`variance_parts`);
  :func:`ratio_interval`: a ratio of two noisy gains (a share of a gain) by test inversion on that variance,
  unbounded when the denominator's interval holds zero; :func:`fieller_interval`: its closed form for paired means
  over seeds (the reference it is tested against);
* :func:`wilson_interval` (a success rate). No McNemar test: the robot trials' picks cluster by
  object and training seed, so they are compared with the object bootstrap and the t-interval;
* :func:`contrast`: the one result type of every experiment (a mean and its intervals, each keyed by what it
  covers: ``seeds_*``, ``objects_*``, ``draws_*``), with one :func:`verdict`, one :func:`interval_text` and one
  :func:`headline` (a metrics file's ``mean``, ``lo``, ``hi``);
* :func:`draw_scope`, :func:`draw_verdict`: the words every report uses for intervals over one draw
  of the data (``data_seed``), which do not cover other draws.
"""

from __future__ import annotations

import numpy as np
from scipy import stats
from scipy.stats import binomtest

#: The range of a difference of two AP values, success rates or AUCs (each in [0, 1]).
DIFFERENCE_RANGE = (-1.0, 1.0)


def t_interval(values, level: float = 0.95, bounds: tuple[float, float] | None = None) -> dict:
    """Mean and two-sided ``level`` t-interval of ``values`` (one per seed); the interval is
    None for fewer than two values, and None too when ``bounds`` (the quantity's range, e.g.
    :data:`DIFFERENCE_RANGE` for a difference of two rates) is given and the interval leaves it:
    too few seeds for a usable interval (``usable`` False). Never clipped: a clipped t-interval
    would claim a coverage it does not have."""
    x = np.asarray([v for v in values if v is not None and np.isfinite(v)], dtype=float)
    n = len(x)
    if n == 0:
        return {"mean": None, "low": None, "high": None, "n_seeds": 0, "usable": False}
    mean = float(x.mean())
    if n < 2:
        return {"mean": mean, "low": None, "high": None, "n_seeds": 1, "usable": False}
    half = float(stats.t.ppf(0.5 + level / 2, n - 1) * x.std(ddof=1) / np.sqrt(n))
    if bounds is not None and (mean - half < bounds[0] or mean + half > bounds[1]):
        return {"mean": mean, "low": None, "high": None, "n_seeds": n, "usable": False}
    return {"mean": mean, "low": mean - half, "high": mean + half, "n_seeds": n, "usable": True}


class ObjectBootstrap:
    """Resamples of the objects (the clusters of the datapoints).

    Parameters
    ----------
    object_ids : (N,) — the object of each datapoint (any sortable labels).
    n_resamples : int — bootstrap resamples.
    seed : int or numpy.random.Generator — seeds a fresh generator; a generator is drawn from as it is.

    Attributes
    ----------
    draws : (n_resamples, n_objects) int — the objects drawn with replacement, one resample per
        row, as indices into the sorted unique ``object_ids``.
    object_counts : (n_resamples, n_objects) float32 — how often each object was drawn.
    object_index : (N,) int — each datapoint's object, as an index into the sorted unique ids.
    """

    def __init__(self, object_ids: np.ndarray, n_resamples: int, seed: int | np.random.Generator) -> None:
        objects, self.object_index = np.unique(np.asarray(object_ids), return_inverse=True)
        rng = np.random.default_rng(seed)
        self.draws = rng.integers(0, len(objects), size=(n_resamples, len(objects)))
        counts = np.zeros((n_resamples, len(objects)), dtype=np.float32)
        np.add.at(counts, (np.arange(n_resamples)[:, None], self.draws), 1.0)
        self.object_counts = counts
        self.n_objects = len(objects)

    def average_precision(self, labels: np.ndarray, scores: np.ndarray) -> np.ndarray:
        """(n_resamples,) AP of ``scores`` (N,) for ``labels`` (N,) under every resample: the same figures as
        :func:`weighted_average_precision` with each datapoint weighted by its object's count (tied scores grouped,
        as sklearn's), computed from the objects' counts up to each threshold that holds a positive, so one network
        costs (R × objects × positive thresholds) rather than (R × N).

        Each datapoint is binned at once by (object, the first threshold holding a positive at or below its score),
        the bins summed up the thresholds, and the positives gained at a threshold read off the running true
        positives (no positive lies between two such thresholds), so the resamples take two products of whole
        counts (exact in float32 while every sum stays below 2²⁴, else in float64) and the precisions are summed a
        cache-sized block of resamples at a time: about 3× faster than the object loop it replaces (48 networks ×
        23,524 datapoints × 68 objects, 1,000 resamples: 12.8 s against 39.4 s on a loaded 2-core machine;
        :meth:`average_precision_by_objects`, kept as the reference), the same figures (equal to 1e-9 by test; bit
        for bit in ``bench/bootstrap_speed.py``)."""
        order = np.argsort(-np.asarray(scores), kind="stable")
        s, y = np.asarray(scores)[order], np.asarray(labels, dtype=bool)[order]
        obj = self.object_index[order]
        group = np.cumsum(np.r_[True, s[1:] != s[:-1]]) - 1  # each datapoint's group of tied scores, highest first
        held = np.unique(group[y])  # the thresholds that hold a positive: only they add to AP
        if len(held) == 0:
            return np.full(len(self.object_counts), np.nan)
        at = np.searchsorted(held, group)  # the first such threshold that counts the datapoint as seen
        keep = at < len(held)
        cells = obj[keep] * len(held) + at[keep]
        size = self.n_objects * len(held)
        seen = np.bincount(cells, minlength=size).reshape(self.n_objects, -1).cumsum(axis=1)
        hits = np.bincount(cells[y[keep]], minlength=size).reshape(self.n_objects, -1).cumsum(axis=1)
        exact32 = float(self.object_counts.sum(axis=1).max()) * float(np.bincount(self.object_index).max()) < 2**24
        dtype = np.float32 if exact32 else np.float64  # whole numbers: exact either way below 2²⁴ (float32)
        counts, hits, seen = self.object_counts.astype(dtype), hits.astype(dtype), seen.astype(dtype)
        tp, seen = counts @ hits, np.maximum(counts @ seen, 1)  # (R, thresholds); 1 where none seen: precision 0
        found = np.zeros(len(counts))
        step = max(1, 2**17 // len(held))  # resamples at a time: (step, thresholds) blocks that stay in the cache
        for r in range(0, len(counts), step):
            positive = np.diff(tp[r : r + step], axis=1, prepend=dtype(0))  # gained at each: whole numbers, exact
            precision = np.divide(tp[r : r + step], seen[r : r + step], dtype=np.float64)
            precision *= positive
            found[r : r + step] = precision.sum(axis=1)
        total = tp[:, -1].astype(float)  # each resample's positives
        out = np.full(len(counts), np.nan)
        np.divide(found, total, out=out, where=total > 0)
        return out

    def average_precision_by_objects(self, labels: np.ndarray, scores: np.ndarray) -> np.ndarray:
        """:meth:`average_precision` as it was computed before, one object at a time (35,000 datapoints of 73
        objects, 2,000 resamples, in about 0.05 s against the weighted AP's 2 s): the reference the faster one is
        tested and timed against (``bench/bootstrap_speed.py``)."""
        order = np.argsort(-np.asarray(scores), kind="stable")
        s, y = np.asarray(scores)[order], np.asarray(labels, dtype=bool)[order]
        obj = self.object_index[order]
        new_group = np.r_[True, s[1:] != s[:-1]]
        group = np.cumsum(new_group) - 1
        starts = np.flatnonzero(new_group)
        ends = np.r_[starts[1:], len(s)]
        held = np.unique(group[y])
        if len(held) == 0:
            return np.full(len(self.object_counts), np.nan)
        lo, hi = starts[held], ends[held]
        seen = np.zeros((self.n_objects, len(held)))
        hits = np.zeros((self.n_objects, len(held)))
        gained = np.zeros((self.n_objects, len(held)))
        for o in np.unique(obj):
            where = np.flatnonzero(obj == o)
            where_pos = where[y[where]]
            seen[o] = np.searchsorted(where, hi)
            hits[o] = np.searchsorted(where_pos, hi)
            gained[o] = hits[o] - np.searchsorted(where_pos, lo)
        counts = self.object_counts.astype(float)
        tp, total_seen, positive = counts @ hits, counts @ seen, counts @ gained  # (R, thresholds)
        precision = np.divide(tp, total_seen, out=np.zeros_like(tp), where=total_seen > 0)
        total = tp[:, -1]
        return np.divide((positive * precision).sum(axis=1), total, out=np.full_like(total, np.nan), where=total > 0)

    def roc_auc(self, labels: np.ndarray, scores: np.ndarray) -> np.ndarray:
        """(n_resamples,) ROC AUC of ``scores`` (N,) for ``labels`` (N,) under every resample
        (NaN where a resample lacks one label)."""
        return weighted_roc_auc(labels, scores, self.object_counts[:, self.object_index])

    def means(self, values: np.ndarray) -> np.ndarray:
        """(n_resamples,) mean of ``values`` (N,), one per datapoint, under every resample: each
        drawn object brings all its datapoints, once per draw."""
        sums = np.bincount(self.object_index, weights=values, minlength=self.n_objects)
        counts = np.bincount(self.object_index, minlength=self.n_objects)
        return (self.object_counts @ sums) / (self.object_counts @ counts)


class PairBootstrap(ObjectBootstrap):
    """The critic study's resamples: every interpolation pair is an object with one value, and
    a value that is NaN (an empty decoded grid) is left out of its resamples.

    Parameters
    ----------
    n_pairs : int — pairs (objects ``0 .. n_pairs − 1``).
    n_resamples : int — bootstrap resamples.
    rng : numpy.random.Generator — the study's generator, drawn from as it is.
    """

    def __init__(self, n_pairs: int, n_resamples: int, rng: np.random.Generator) -> None:
        super().__init__(np.arange(n_pairs), n_resamples, rng)

    def means(self, values: np.ndarray) -> np.ndarray:
        """(n_resamples,) mean of the finite ``values`` (n_pairs,) of every resample's drawn pairs;
        NaN for a resample without a finite value."""
        drawn = values[self.draws]  # (n_resamples, P)
        counts = np.isfinite(drawn).sum(axis=1)
        sums = np.where(np.isfinite(drawn), drawn, 0.0).sum(axis=1)
        return np.divide(sums, counts, out=np.full(len(drawn), np.nan), where=counts > 0)


def weighted_average_precision(labels: np.ndarray, scores: np.ndarray, weights: np.ndarray) -> np.ndarray:
    """Average Precision of ``scores`` (N,) for ``labels`` (N,) with datapoint ``weights`` (..., N), as sklearn's
    ``average_precision_score(labels, scores, sample_weight=w)``: Σ over the distinct scores, highest first, of the
    recall gained at that threshold times the precision there, tied scores taken together as one threshold (so the
    result does not depend on the order of the datapoints). (...,); NaN where no positive has weight."""
    order = np.argsort(-np.asarray(scores), kind="stable")
    s, y = np.asarray(scores)[order], np.asarray(labels, dtype=bool)[order]
    w = np.asarray(weights)  # float32 bootstrap counts stay float32: (R, N) of them is the memory that counts
    w = (w if np.issubdtype(w.dtype, np.floating) else w.astype(float))[..., order]
    starts = np.flatnonzero(np.r_[True, s[1:] != s[:-1]])  # groups of tied scores, highest first
    positive = np.add.reduceat(w * y, starts, axis=-1)  # (..., G) positive weight per threshold
    tp, seen = np.cumsum(positive, axis=-1), np.cumsum(np.add.reduceat(w, starts, axis=-1), axis=-1)
    precision = np.divide(tp, seen, out=np.zeros_like(tp), where=seen > 0)
    total = tp[..., -1]
    return np.divide((positive * precision).sum(axis=-1), total, out=np.full_like(total, np.nan), where=total > 0)


def weighted_roc_auc(labels: np.ndarray, scores: np.ndarray, weights: np.ndarray) -> np.ndarray:
    """ROC AUC of ``scores`` (N,) for ``labels`` (N,) with datapoint ``weights`` (..., N): the
    weighted share of (positive, negative) pairs that the scores order correctly, a tie counting
    half (sklearn's ``roc_auc_score`` with ``sample_weight``). (...,); NaN where either label
    has no weight."""
    order = np.argsort(np.asarray(scores), kind="stable")
    s, y = np.asarray(scores)[order], np.asarray(labels, dtype=bool)[order]
    w = np.asarray(weights, dtype=float)[..., order]
    starts = np.flatnonzero(np.r_[True, s[1:] != s[:-1]])  # groups of tied scores
    positive = np.add.reduceat(w * y, starts, axis=-1)
    negative = np.add.reduceat(w * ~y, starts, axis=-1)
    below = np.cumsum(negative, axis=-1) - negative
    pairs = positive.sum(axis=-1) * negative.sum(axis=-1)
    ordered = (positive * (below + 0.5 * negative)).sum(axis=-1)
    return np.divide(ordered, pairs, out=np.full_like(pairs, np.nan), where=pairs > 0)


def percentile_interval(samples: np.ndarray, level: float = 0.95) -> tuple[float | None, float | None]:
    """Two-sided percentile interval of bootstrap ``samples`` (NaNs left out)."""
    x = np.asarray(samples, dtype=float)
    x = x[np.isfinite(x)]
    if len(x) == 0:
        return None, None
    low, high = np.quantile(x, [0.5 - level / 2, 0.5 + level / 2])
    return float(low), float(high)


def mean_interval(values: np.ndarray, boot: ObjectBootstrap, level: float = 0.95) -> dict[str, float | None]:
    """Mean of the finite ``values`` (N,) and the two-sided ``level`` percentile interval of
    their mean over the resamples of ``boot`` (:meth:`ObjectBootstrap.means`), as a :func:`contrast` over
    ``objects``; all None when no value is finite."""
    finite = np.isfinite(values)
    if not finite.any():
        return contrast(None, "objects")
    return contrast(float(np.mean(values[finite])), "objects", objects=percentile_interval(boot.means(values), level))


def paired_contrast(
    a: np.ndarray, b: np.ndarray, boot: ObjectBootstrap, level: float = 0.95
) -> dict[str, float | None]:
    """``a − b`` on paired datapoints (both (N,), the same datapoints of the same objects): the
    mean difference and its bootstrap interval (:func:`mean_interval`). A datapoint whose
    difference is NaN (either value NaN) is left out."""
    return mean_interval(a - b, boot, level)


INTERVALS = ("seeds", "objects", "draws")
"""What a contrast's intervals cover, the prefix of their keys: ``seeds`` the 95% t-interval over paired training
seeds; ``objects`` the 95% cluster bootstrap over test objects (shapes; the critic study's interpolation pairs);
``draws`` the 95% interval over data draws × training seeds × test objects (:func:`nested_t_interval`; with one draw,
over its seeds and the test objects)."""


def contrast(mean: float | None, over: str, n_seeds: int | None = None, n_draws: int = 1, **intervals) -> dict:
    """The one result type of every experiment: a paired difference (or one figure) ``mean`` with its 95% intervals,
    each keyed by what it covers (:data:`INTERVALS`): ``seeds_low``, ``seeds_high``, ``objects_low``,
    ``objects_high``, ``draws_low``, ``draws_high`` (None where not measured). ``over`` names the interval that its
    verdict (:func:`verdict`), its text (:func:`interval_text`) and its metrics file (:func:`headline`) read;
    ``n_seeds``, ``n_draws``. ``intervals``: ``seeds=(low, high)`` and the like, then any other keys the experiment
    keeps (``sd``, ``per_seed``, ``n_trials``…), in that order after the fixed ones."""
    if over not in INTERVALS:
        raise ValueError(f"over must be one of {INTERVALS}, not {over!r}")
    out = {"mean": mean}
    for name in INTERVALS:
        low, high = intervals.pop(name, None) or (None, None)
        out |= {f"{name}_low": low, f"{name}_high": high}
    return out | {"over": over, "n_seeds": n_seeds, "n_draws": n_draws} | intervals


def nested_contrast(nested: dict, **extra) -> dict:
    """A :func:`nested_t_interval` result as a :func:`contrast` over ``draws``; ``extra`` keys kept after its own."""
    draws = (nested["low"], nested["high"])
    return contrast(nested["mean"], "draws", nested["n_seeds"], nested["n_draws"], draws=draws, **extra)


def interval(c: dict) -> tuple[float | None, float | None]:
    """The (low, high) of the interval a :func:`contrast` is judged by (its ``over``)."""
    return c[f"{c['over']}_low"], c[f"{c['over']}_high"]


def verdict(c: dict) -> str:
    """A :func:`contrast` in words (:func:`draw_verdict` of its :func:`interval` and ``n_draws``)."""
    return draw_verdict(*interval(c), c["n_draws"])


def interval_text(c: dict | None, spec: str = "+.4f", over: str | None = None) -> str:
    """``mean [low, high]`` of a :func:`contrast` (its ``over`` interval, or ``over``'s), "n/a" for what is missing."""
    if c is None or c.get("mean") is None:
        return "n/a"
    low, high = interval(c if over is None else {**c, "over": over})
    ends = [format(v, spec) if v is not None else "n/a" for v in (low, high)]
    return f"{format(c['mean'], spec)} [{ends[0]}, {ends[1]}]"


def headline(c: dict) -> dict[str, float | None]:
    """A :func:`contrast` as a metrics file holds it: ``mean`` and its :func:`interval` as ``lo``, ``hi``, rounded to 5
    decimals; None stays None. The same three keys in every metrics file, so ``dvc metrics show`` lines every
    experiment's contrasts up in three columns; the report beside it says what the interval covers (``over``)."""
    values = {"mean": c.get("mean"), "lo": interval(c)[0], "hi": interval(c)[1]}
    return {k: None if v is None else round(float(v), 5) for k, v in values.items()}


#: Where each experiment is run over several draws of the data: (command, section of docs/results.md).
OVER_DRAWS = {
    "ap": ("graspaug study attribution --draws 0 1 2", "Over three draws of the data"),
    "lifelong": (
        "graspaug study lifelong --draws 0 1 2",
        "The lifelong loop: generating from the planner's failures",
    ),
    "sim": (
        "graspaug study cell-ranking --grasps reports/grasp_calibration/grasps.csv --projects . <draw1> <draw2>",
        "The networks rank the cell's outcomes: the positive control shows",
    ),
}


def draw_scope(data_seed: int, seeds, experiment: str) -> str:
    """The sentence that bounds a report's intervals over one draw of the data: they cover the draw
    ``data_seed`` (its base sets, validation shapes and generated pools) and the training ``seeds``
    (``gqcnn.seeds``), not other draws; ``experiment`` (a key of :data:`OVER_DRAWS`) names the command
    that runs it over several draws and the section of docs/results.md that holds that result."""
    command, section = OVER_DRAWS[experiment]
    return (
        f"One draw of the data: every interval here covers the draw `data_seed` = {data_seed} and training seeds "
        f"{list(seeds)} (`gqcnn.seeds`) and does not cover other draws of the base sets, validation shapes and "
        f"generated pools, so each verdict holds for this draw only. Over several draws: `{command}` "
        f'(docs/results.md, "{section}").'
    )


def draw_verdict(low: float | None, high: float | None, n_draws: int = 1) -> str:
    """A 95% interval [``low``, ``high``] in words: a gain or a loss when it lies above or below zero, else
    no effect we can claim; an interval over one draw of the data is scoped to that draw
    (:func:`draw_scope` says which), one over several draws says how many. Without an interval (an end None: one
    seed, or a network without a value) there is no verdict, and the words say so."""
    if low is None or high is None:
        return "no interval (one seed, or a missing value): no verdict"
    scope = "in this draw of the data" if n_draws == 1 else f"over {n_draws} draws of the data"
    if low is not None and low > 0:
        return f"a gain {scope}"
    if high is not None and high < 0:
        return f"a loss {scope}"
    return f"no effect we can claim {scope}"


def wilson_interval(successes: int, attempts: int, confidence: float = 0.95) -> tuple[float, float]:
    """Wilson score interval of a success rate (scipy); (0, 1) when there were no attempts."""
    if attempts == 0:
        return 0.0, 1.0
    ci = binomtest(int(successes), int(attempts)).proportion_ci(confidence_level=confidence, method="wilson")
    return float(ci.low), float(ci.high)


def variance_parts(full: np.ndarray, resampled: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The two parts of the variance of a contrast's mean over data draws × training seeds × test objects.

    Parameters
    ----------
    full : (D, S) float — the contrast of draw d, training seed s on all test objects
    resampled : (D, S, R) float — the same under each of R resamples of the test objects, the r-th resample the same
        for every cell (:class:`ObjectBootstrap`)

    Returns
    -------
    units : (U,) float — the replicates of the draws-and-seeds part: the per-draw means over seeds when there are
        several draws (U = D), else the seeds of the one draw (U = S)
    objects : (R,) float — the mean over all cells under each object resample (NaN where a cell is)
    """
    full, resampled = np.asarray(full, dtype=float), np.asarray(resampled, dtype=float)
    if full.ndim != 2 or resampled.shape[:2] != full.shape or resampled.ndim != 3:
        raise ValueError(f"variance_parts: full {full.shape} and resampled {resampled.shape}, need (D, S), (D, S, R)")
    units = full.mean(axis=1) if len(full) > 1 else full[0]
    return units, resampled.mean(axis=(0, 1))


def nested_t_interval(full: np.ndarray, resampled: np.ndarray, level: float = 0.95) -> dict:
    """A contrast's mean over data draws × training seeds with the one interval every verdict reads: the half-widths
    of its two parts of variance, each at its own quantile, added in quadrature.

    * Draws and seeds (the replicates, :func:`variance_parts`): the D per-draw means over seeds when D > 1, else the
      S seeds of the one draw; their variance of the mean s²/U at the t quantile on U − 1 degrees of freedom.
    * Test objects: the variance of the mean of all cells over the object resamples (the same resample for every
      network, so a contrast's networks are paired), at the normal quantile.

    The interval is mean ± √(t² · s²/U + z² · v_objects). What it covers, at ``level``: the contrast's expected value
    over training seeds and test objects, and over draws of the data (base sets, validation shapes, pools) when
    D > 1; with one draw it covers that draw only. Exactly the t-interval when only seeds (or draws) vary; the
    normal bootstrap interval when only test objects vary; wider than either part alone when both do (conservative:
    a seed-by-object interaction is counted in both parts). Its coverage is checked by simulation
    (``tests/experiments/test_coverage.py``, the table in docs/results.md): at least 93% at 4 seeds of 1 or 3 draws,
    where the percentile bootstrap over draws, seeds and objects that it replaces covered 75–91% when seeds varied.

    Parameters
    ----------
    full : (D, S) float — the contrast of draw d, training seed s on all test objects (AP, or any unit)
    resampled : (D, S, R) float — the same under each of R object resamples; a resample with a NaN cell is left out
    level : float — the interval's coverage

    Returns
    -------
    dict — ``mean`` (of ``full``; None if a cell is not finite), ``low``, ``high`` (None without replicates: one
    seed of one draw, or a non-finite cell), ``n_draws``, ``n_seeds``, ``replicates_sd`` (s), ``objects_sd``
    (√v_objects)
    """
    units, objects = variance_parts(full, resampled)
    n_draws, n_seeds = np.shape(full)
    out = {"mean": None, "low": None, "high": None, "n_draws": n_draws, "n_seeds": n_seeds}
    out |= {"replicates_sd": None, "objects_sd": None}
    if not np.isfinite(full).all():  # a network without a test AP: no mean
        return out
    out["mean"] = float(np.mean(full))
    objects = objects[np.isfinite(objects)]
    if len(units) < 2 or len(objects) < 2:  # one seed of one draw: no replicate, no interval
        return out
    t2, z2 = _quantiles2(len(units), level)
    half = float(np.sqrt(t2 * units.var(ddof=1) / len(units) + z2 * objects.var(ddof=1)))
    sds = {"replicates_sd": float(units.std(ddof=1)), "objects_sd": float(objects.std(ddof=1))}
    return out | {"low": out["mean"] - half, "high": out["mean"] + half} | sds


def _quantiles2(n_units: int, level: float) -> tuple[float, float]:
    """The squared two-sided ``level`` quantiles of :func:`nested_t_interval`: t on ``n_units`` − 1 degrees of freedom
    (the replicates), normal (the test objects)."""
    return float(stats.t.ppf(0.5 + level / 2, n_units - 1) ** 2), float(stats.norm.ppf(0.5 + level / 2) ** 2)


def fieller_interval(x, y, level: float = 0.95) -> dict:
    """Fieller's interval for the ratio of two paired means, mean(x) / mean(y) (one pair per
    training seed: e.g. augmentation's gain over the same number of real shapes' gain).

    The interval holds every θ whose paired difference x − θ·y has a mean within the t-interval
    of zero: (x̄ − θȳ)² ≤ t² (s_xx − 2θ s_xy + θ² s_yy) / n. When ȳ itself is not clearly
    nonzero (its own t-test at ``level`` does not reject zero) the set is unbounded and both ends
    are None: the data then say nothing about the ratio's size.

    Returns
    -------
    dict — ``ratio`` (x̄ / ȳ), ``low``, ``high``, ``bounded`` (False, every figure None, on a non-finite input)
    """
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    n = len(x)
    if n < 2 or not np.any(y) or not (np.isfinite(x).all() and np.isfinite(y).all()):  # NaN in: nothing bounded out
        return {"ratio": None, "low": None, "high": None, "bounded": False}
    mx, my = x.mean(), y.mean()
    cov = np.cov(x, y, ddof=1)
    t2 = stats.t.ppf(0.5 + level / 2, n - 1) ** 2 / n
    a = my**2 - t2 * cov[1, 1]  # a θ² − 2 b θ + c ≤ 0
    b = mx * my - t2 * cov[0, 1]
    c = mx**2 - t2 * cov[0, 0]
    ratio = float(mx / my) if my else None
    disc = b * b - a * c
    if a <= 0 or disc < 0:
        return {"ratio": ratio, "low": None, "high": None, "bounded": False}
    root = np.sqrt(disc)
    return {"ratio": ratio, "low": float((b - root) / a), "high": float((b + root) / a), "bounded": True}


def ratio_interval(
    numerator: np.ndarray,
    resampled_numerator: np.ndarray,
    denominator: np.ndarray,
    resampled_denominator: np.ndarray,
    level: float = 0.95,
) -> dict:
    """A ratio of two noisy gains, mean(numerator) / mean(denominator) (e.g. a pool's AP gain over no augmentation
    divided by as many real shapes' gain: a share), with a ``level`` interval by test inversion (Fieller's idea, the
    one method for every share in the package) of :func:`nested_t_interval`.

    θ is in the interval when :func:`nested_t_interval` of the paired difference ``numerator − θ·denominator`` (cell
    by cell, resample by resample) holds zero: (x̄ − θȳ)² ≤ t² V_u(θ) + z² V_o(θ), with V_u and V_o the replicates' and
    the test objects' variances of the difference, each a quadratic in θ (from the (2, 2) covariances of the two
    gains' replicates and resamples). So the set is {θ : a θ² − 2 b θ + c ≤ 0}: an interval when a > 0, which is
    exactly when the denominator's own :func:`nested_t_interval` excludes zero; otherwise it is unbounded (an
    unbounded interval or the complement of one) and both ends are None: the data then say nothing about the
    ratio's size. With one draw and no object spread it is :func:`fieller_interval` of the seeds' values. Nothing
    larger than (R,) is kept.

    Parameters
    ----------
    numerator, denominator : (D, S) float — the two gains of draw d, training seed s on all test objects (AP, or any
        unit: the ratio has none)
    resampled_numerator, resampled_denominator : (D, S, R) float — the same under R object resamples, the same
        resamples for both; a resample with a NaN cell in either is left out
    level : float — the interval's coverage

    Returns
    -------
    dict — ``share`` (x̄ / ȳ; None when ȳ is 0 or a cell not finite), ``low``, ``high`` (None when unbounded),
    ``bounded``, and the denominator's own :func:`nested_t_interval` ends ``denominator_low``, ``denominator_high``
    """
    ux, bx = variance_parts(numerator, resampled_numerator)
    uy, by = variance_parts(denominator, resampled_denominator)
    keep = np.isfinite(bx) & np.isfinite(by)
    den = nested_t_interval(denominator, np.where(keep, resampled_denominator, np.nan), level)
    out = {"share": None, "low": None, "high": None, "bounded": False}
    out |= {"denominator_low": den["low"], "denominator_high": den["high"]}
    if not (np.isfinite(numerator).all() and np.isfinite(denominator).all()) or np.mean(denominator) == 0:
        return out
    mx, my = float(np.mean(numerator)), float(np.mean(denominator))
    out["share"] = mx / my
    if den["low"] is None or den["low"] <= 0 <= den["high"] or keep.sum() < 2:
        return out
    t2, z2 = _quantiles2(len(ux), level)
    v = t2 * np.cov(ux, uy, ddof=1) / len(ux) + z2 * np.cov(bx[keep], by[keep], ddof=1)  # (2, 2)
    a, b, c = my**2 - v[1, 1], mx * my - v[0, 1], mx**2 - v[0, 0]  # a θ² − 2 b θ + c ≤ 0
    disc = b * b - a * c
    if a <= 0 or disc < 0:
        return out
    root = np.sqrt(disc)
    return out | {"low": float((b - root) / a), "high": float((b + root) / a), "bounded": True}


def share_headline(share: dict) -> dict[str, float | None]:
    """A :func:`ratio_interval` as a metrics file holds it, under :func:`headline`'s keys: ``mean`` (the share),
    ``lo``, ``hi`` (None when unbounded), rounded to 5 decimals."""
    values = {"mean": share.get("share"), "lo": share.get("low"), "hi": share.get("high")}
    return {k: None if v is None else round(float(v), 5) for k, v in values.items()}


def share_text(share: dict, spec: str = "+.0%") -> str:
    """A :func:`ratio_interval` in words: ``share [low, high]``, or ``share [unbounded]`` (``n/a`` without a
    ratio); what a share is read beside: its denominator, printed by the caller."""
    if share is None or share.get("share") is None:
        return "n/a"
    if not share["bounded"]:
        return f"{format(share['share'], spec)} [unbounded]"
    return f"{format(share['share'], spec)} [{format(share['low'], spec)}, {format(share['high'], spec)}]"
