"""The statistics of the three experiments (GQ-CNN AP, critic study, simulated trials).

* :func:`t_interval`: mean and t-interval over training seeds (the replicates);
* :class:`ObjectBootstrap`: the cluster bootstrap. Each resample draws the clusters (test
  objects; the critic study's interpolation pairs: :class:`PairBootstrap`) with replacement, as
  many as there are, and every datapoint of a drawn cluster comes along;
* :func:`percentile_interval`, :func:`mean_interval`, :func:`paired_contrast`: the mean of values
  (of paired differences) with its percentile bootstrap interval;
* :func:`weighted_average_precision`: Average Precision as sklearn's (step-wise, no
  interpolation): the mean over positives of the precision at their rank, with datapoint
  weights for the bootstrap; :func:`weighted_roc_auc`: ROC AUC as sklearn's (ties count
  half), with datapoint weights;
* :func:`nested_interval`: one interval over data draws, training seeds and test objects (a
  hierarchical bootstrap); :func:`ratio_interval`: a ratio of two noisy gains (a share of a gain) by test
  inversion over their bootstrap, unbounded when the denominator's interval holds zero; :func:`fieller_interval`:
  its closed form for paired means over seeds (the reference it is tested against);
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
        """(n_resamples,) AP of ``scores`` (N,) for ``labels`` (N,) under every resample."""
        order = np.argsort(-np.asarray(scores), kind="stable")
        y = np.asarray(labels, dtype=np.float32)[order]
        w = self.object_counts[:, self.object_index[order]]
        return weighted_average_precision(y, w)

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


def weighted_average_precision(labels_sorted: np.ndarray, weights: np.ndarray) -> np.ndarray:
    """AP of datapoints already sorted by descending score, with weights (..., N): the
    weighted mean over positives of the precision at their rank."""
    tp = np.cumsum(weights * labels_sorted, axis=-1)
    seen = np.cumsum(weights, axis=-1)
    precision = np.divide(tp, seen, out=np.zeros_like(tp), where=seen > 0)
    positives = tp[..., -1]
    return np.divide(
        (precision * weights * labels_sorted).sum(axis=-1),
        positives,
        out=np.full_like(positives, np.nan),
        where=positives > 0,
    )


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
``draws`` the 95% nested bootstrap over data draws × training seeds × test objects."""


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
    """A :func:`nested_interval` result as a :func:`contrast` over ``draws``; ``extra`` keys kept after its own."""
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
    (:func:`draw_scope` says which), one over several draws says how many."""
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


def nested_indices(n_draws: int, n_seeds: int, n_resamples: int, rng: np.random.Generator):
    """The resamples of a hierarchical bootstrap over data draws and training seeds: (draws
    (R, D), seeds (R, D, S)): resample r draws D draws with replacement and, within each drawn
    draw, S of its seeds with replacement."""
    draws = rng.integers(0, n_draws, size=(n_resamples, n_draws))
    return draws, rng.integers(0, n_seeds, size=(n_resamples, n_draws, n_seeds))


def nested_means(resampled: np.ndarray, indices) -> np.ndarray:
    """(R,) the mean over each resample's drawn (draw, seed) cells of ``resampled`` (D, S, R): cell
    (d, s) under the r-th resample of the test objects; ``indices``: :func:`nested_indices`."""
    draws, seeds = indices
    r = np.arange(len(draws))[:, None, None]
    return np.asarray(resampled, dtype=float)[draws[:, :, None], seeds, r].mean(axis=(1, 2))


def nested_interval(full: np.ndarray, resampled: np.ndarray, rng: np.random.Generator, level: float = 0.95) -> dict:
    """A contrast's mean over data draws × training seeds with one interval that covers the draws,
    the seeds and the test objects: a hierarchical percentile bootstrap.

    Each resample r draws D data draws with replacement, within each drawn draw S of its seeds
    with replacement, and takes the contrast of every drawn (draw, seed) under the r-th resample
    of the test objects (the same object resample for every network, as :class:`ObjectBootstrap`
    gives); the statistic is the mean of those. With few draws (3) the interval is on the narrow
    side, as a bootstrap over few clusters is; it says so by ``n_draws``.

    Parameters
    ----------
    full : (D, S) float — the contrast of draw d, training seed s on all test objects
    resampled : (D, S, R) float — the same under each of R object resamples
    rng : numpy.random.Generator — draws the draws and seeds

    Returns
    -------
    dict — ``mean`` (of ``full``; None if a cell is not finite), ``low``, ``high``, ``n_draws``, ``n_seeds``
    """
    full, resampled = np.asarray(full, dtype=float), np.asarray(resampled, dtype=float)
    n_draws, n_seeds, n_resamples = resampled.shape
    low, high = percentile_interval(nested_means(resampled, nested_indices(n_draws, n_seeds, n_resamples, rng)), level)
    mean = float(full.mean()) if np.isfinite(full).all() else None  # a network without a test AP: no mean
    return {"mean": mean, "low": low, "high": high, "n_draws": n_draws, "n_seeds": n_seeds}


def fieller_interval(x, y, level: float = 0.95) -> dict:
    """Fieller's interval for the ratio of two paired means, mean(x) / mean(y) (one pair per
    training seed: e.g. augmentation's gain over the same number of real shapes' gain).

    The interval holds every θ whose paired difference x − θ·y has a mean within the t-interval
    of zero: (x̄ − θȳ)² ≤ t² (s_xx − 2θ s_xy + θ² s_yy) / n. When ȳ itself is not clearly
    nonzero (its own t-test at ``level`` does not reject zero) the set is unbounded and both ends
    are None: the data then say nothing about the ratio's size.

    Returns
    -------
    dict — ``ratio`` (x̄ / ȳ), ``low``, ``high``, ``bounded``
    """
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    n = len(x)
    if n < 2 or not np.any(y):
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
    numerator: float,
    denominator: float,
    resampled_numerator: np.ndarray,
    resampled_denominator: np.ndarray,
    level: float = 0.95,
) -> dict:
    """A ratio of two noisy gains, numerator / denominator (e.g. a pool's AP gain over no augmentation divided by as
    many real shapes' gain: a share), with a ``level`` interval by test inversion over one bootstrap (Fieller's
    idea, the one method for every share in the package).

    θ is in the interval when the test of ``numerator − θ·denominator = 0`` does not reject: when 0 lies within the
    percentile interval of its resamples, i.e. at least (1 − level)/2 of the resampled
    ``resampled_numerator − θ·resampled_denominator`` lie at or below 0 and as many at or above it. The set of such
    θ is an interval when the denominator is clearly nonzero (then it is the percentile interval of the resampled
    ratios), and unbounded (an unbounded interval or the complement of one) when the denominator's own percentile
    interval holds zero: the data then say nothing about the ratio's size, and both ends are None. The percentile
    interval of the resampled ratios alone is not used: with a denominator near zero it is bounded and may exclude
    its own estimate (issue #58). :func:`fieller_interval` is the closed form of the same idea for paired means.

    Parameters
    ----------
    numerator, denominator : float — the two gains on all the data (AP, or any unit: the ratio has none)
    resampled_numerator, resampled_denominator : (R,) float — the same under R resamples, the same resamples for
        both (e.g. :func:`nested_means` with one set of :func:`nested_indices`); NaN resamples are left out
    level : float — the interval's coverage

    Returns
    -------
    dict — ``share`` (numerator / denominator; None when the denominator is 0 or either is not finite), ``low``,
    ``high`` (None when unbounded), ``bounded``, and the denominator's own percentile interval
    ``denominator_low``, ``denominator_high``
    """
    x, y = np.asarray(resampled_numerator, dtype=float), np.asarray(resampled_denominator, dtype=float)
    if x.shape != y.shape or x.ndim != 1:
        raise ValueError(f"ratio_interval: resamples of shapes {x.shape} and {y.shape}, need two equal (R,)")
    keep = np.isfinite(x) & np.isfinite(y)
    x, y = x[keep], y[keep]
    finite = np.isfinite(numerator) and np.isfinite(denominator) and denominator != 0
    ratio = float(numerator / denominator) if finite else None
    den_low, den_high = percentile_interval(y, level)
    unbounded = {"share": ratio, "low": None, "high": None, "bounded": False}
    den = {"denominator_low": den_low, "denominator_high": den_high}
    if len(y) == 0 or den_low is None or den_low <= 0 <= den_high:
        return unbounded | den
    tail = (1 - level) / 2

    def accepted(theta: np.ndarray) -> np.ndarray:  # (T,) → (T,) bool: 0 within the differences' percentiles
        diff = x[None, :] - theta[:, None] * y[None, :]  # (T, R)
        return ((diff <= 0).mean(axis=1) >= tail) & ((diff >= 0).mean(axis=1) >= tail)

    nonzero = y != 0
    breaks = np.unique(x[nonzero] / y[nonzero])  # where a resample's difference changes sign
    far = 10 * (np.abs(breaks).max() + 1)
    between = (breaks[:-1] + breaks[1:]) / 2
    if accepted(np.array([-far, far])).any():  # open at an end: unbounded
        return unbounded | den
    points = np.concatenate([breaks, between])
    ok = points[accepted(points)]
    if len(ok) == 0:
        return unbounded | den
    return {"share": ratio, "low": float(ok.min()), "high": float(ok.max()), "bounded": True} | den


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
