"""The confirmatory study's statistics: a plan fixed before its data, then one test per hypothesis over independent
draws (issue #74).

A draw (``data_seed``) redraws everything random: the train/test split, the base sets, validation shapes, pools and
the networks' initial weights (training seeds nested in draws). The draws are then independent and identically
distributed, and a contrast's unit is the draw: its mean over the draw's training seeds of the paired test-AP
difference, on that draw's own test objects. The interval and test are a plain one-sample t over those D draw means
(D − 1 degrees of freedom), which covers training seeds, data draws and test objects at once, because each draw mean
carries all three. :func:`simulate_coverage` checks that claim on the exploratory study's networks.

The design, in the order it is read (:func:`read_plan_result`):

1. the positive control (``real_data``: 150 vs 50 real objects) first: it "shows" when its two-sided p < alpha and
   its mean is positive; if it does not, every verdict is "uninformative", never "negative" (fixed sequence);
2. the one primary hypothesis (``targeted_vs_none@50``) at alpha, two-sided;
3. the secondary ones, Holm within them (:func:`holm`), named as secondary; ``targeted_vs_random@50`` also gets an
   equivalence verdict by two one-sided tests (:func:`tost`) against the plan's margin;
4. the exchange rate (what the targeted shapes are worth in real objects) read only inside the measured real-shape
   curve (:func:`exchange_rate_on_curve`).

Power before the first draw: :func:`variance_components` of a contrast from the exploratory tables, then
:func:`draws_for_power` and :func:`seeds_for_cost`.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
import pandas as pd
from scipy import stats

#: The verdict words of a plan's tests (each plan may give its own sentences around them).
UNINFORMATIVE = "uninformative"


def draw_test(draw_means: Sequence[float], level: float = 0.95) -> dict:
    """One-sample two-sided t of a contrast's per-draw means (one value per independent draw).

    Returns
    -------
    dict — ``mean``, ``low``, ``high`` (the ``level`` t-interval; None with fewer than 2 draws), ``p`` (two-sided,
    against 0), ``sd`` (of the draw means), ``n_draws``, ``per_draw`` (the values, in order)
    """
    x = np.asarray([v for v in draw_means], dtype=float)
    out = {"mean": None, "low": None, "high": None, "p": None, "sd": None, "n_draws": int(len(x))}
    out["per_draw"] = [float(v) for v in x]
    if len(x) == 0 or not np.isfinite(x).all():
        return out
    out["mean"] = float(x.mean())
    if len(x) < 2:
        return out
    sd = float(x.std(ddof=1))
    se = sd / np.sqrt(len(x))
    half = float(stats.t.ppf(0.5 + level / 2, len(x) - 1) * se)
    p = 1.0 if se == 0 else float(2 * stats.t.sf(abs(out["mean"]) / se, len(x) - 1))
    return out | {"low": out["mean"] - half, "high": out["mean"] + half, "p": p, "sd": sd}


def tost(draw_means: Sequence[float], margin: float, alpha: float = 0.05) -> dict:
    """Two one-sided t-tests of equivalence within ±``margin`` over the per-draw means: ``p`` (the larger of the two
    one-sided p-values; equivalence is shown when it is below ``alpha``, i.e. the (1 − 2 alpha) interval lies inside
    ±margin), the (1 − 2 alpha) interval ``low``, ``high``."""
    x = np.asarray(draw_means, dtype=float)
    if len(x) < 2 or not np.isfinite(x).all():
        return {"p": None, "low": None, "high": None, "margin": margin}
    mean, se, df = float(x.mean()), float(x.std(ddof=1) / np.sqrt(len(x))), len(x) - 1
    if se == 0:
        p = 0.0 if abs(mean) < margin else 1.0
    else:
        p = float(max(stats.t.sf((mean + margin) / se, df), stats.t.cdf((mean - margin) / se, df)))
    half = float(stats.t.ppf(1 - alpha, df) * se)
    return {"p": p, "low": mean - half, "high": mean + half, "margin": margin, "level": 1 - 2 * alpha}


def draw_sensitivity(draw_means: Sequence[float], level: float = 0.95) -> dict | None:
    """How far a contrast over draws rests on single draws: an exploratory look after the plan's test, no verdict.

    Returns
    -------
    dict — ``positive`` (draws above 0) of ``n_draws``, ``wilcoxon_p`` (the signed-rank test against 0, two-sided),
    ``loo_p`` (the least and the largest :func:`draw_test` p with each draw left out in turn); None with fewer than
    3 draws or none away from 0
    """
    x = np.asarray(draw_means, dtype=float)
    if len(x) < 3 or not np.isfinite(x).all() or not x.any():
        return None
    left_out = [draw_test(np.delete(x, i), level)["p"] for i in range(len(x))]
    return {
        "positive": int((x > 0).sum()),
        "n_draws": int(len(x)),
        "wilcoxon_p": float(stats.wilcoxon(x).pvalue),
        "loo_p": (float(min(left_out)), float(max(left_out))),
    }


def holm(pvalues: Mapping[str, float | None]) -> dict[str, float | None]:
    """Holm's step-down adjusted p-values (a None p stays None and counts in no step)."""
    named = sorted(((p, k) for k, p in pvalues.items() if p is not None), key=lambda t: t[0])
    out: dict[str, float | None] = {k: None for k in pvalues}
    running, m = 0.0, len(named)
    for i, (p, k) in enumerate(named):
        running = max(running, min(1.0, (m - i) * p))
        out[k] = running
    return out


def equivalence_verdict(difference: dict, equivalence: dict, alpha: float, adjusted_p: float | None) -> str:
    """``targeted_vs_random``'s verdict: "different" (the Holm-adjusted difference test below ``alpha``),
    "equivalent within ±m" (TOST below ``alpha``), else "undetermined" (neither: too few draws to tell)."""
    if adjusted_p is not None and adjusted_p < alpha:
        return "different"
    if equivalence.get("p") is not None and equivalence["p"] < alpha:
        return f"equivalent within ±{equivalence['margin']:g}"
    return "undetermined"


def variance_components(full: np.ndarray, resampled: np.ndarray) -> dict:
    """A contrast's variance parts from a study with several draws and seeds on one test set (the exploratory one).

    Parameters
    ----------
    full : (D, S) float — the contrast of draw d, training seed s on all test objects
    resampled : (D, S, R) float — the same under R object resamples (the same resample in every cell)

    Returns
    -------
    dict — ``seed_sd`` (within a draw, pooled over draws), ``draw_sd`` (between draws beyond what seeds explain;
    0 when the estimate is negative), ``object_sd`` (of one network pair's difference over test-object resamples,
    averaged over cells: what a new test set of the same size adds to a draw's mean), ``mean``
    """
    full, resampled = np.asarray(full, dtype=float), np.asarray(resampled, dtype=float)
    d, s = full.shape
    seed_var = float(full.var(axis=1, ddof=1).mean()) if s > 1 else 0.0
    draw_var = float(full.mean(axis=1).var(ddof=1) - seed_var / s) if d > 1 else 0.0
    # a new test set per draw moves all of a draw's seeds together: the variance of the seeds' mean over resamples
    object_var = float(np.nanvar(np.nanmean(resampled, axis=1), axis=-1, ddof=1).mean())
    return {
        "mean": float(full.mean()),
        "seed_sd": float(np.sqrt(seed_var)),
        "draw_sd": float(np.sqrt(max(draw_var, 0.0))),
        "object_sd": float(np.sqrt(object_var)),
        "n_draws": int(d),
        "n_seeds": int(s),
    }


def draw_mean_sd(components: Mapping, seeds: int) -> float:
    """SD of one draw's mean over ``seeds`` training seeds when every draw has its own split and test objects."""
    c = components
    return float(np.sqrt(c["draw_sd"] ** 2 + c["object_sd"] ** 2 + c["seed_sd"] ** 2 / seeds))


def power(n_draws: int, sd: float, effect: float, alpha: float = 0.05) -> float:
    """Power of the two-sided one-sample t over ``n_draws`` draw means of SD ``sd`` against a true mean ``effect``
    (noncentral t)."""
    if n_draws < 2:
        return 0.0
    df, nc = n_draws - 1, effect / (sd / np.sqrt(n_draws))
    crit = stats.t.ppf(1 - alpha / 2, df)
    value = stats.nct.sf(crit, df, nc) + stats.nct.cdf(-crit, df, nc)
    return float(value) if np.isfinite(value) else float(stats.norm.sf(crit - nc) + stats.norm.cdf(-crit - nc))


def draws_for_power(sd: float, effect: float, alpha: float = 0.05, target: float = 0.8, most: int = 1000) -> int:
    """The fewest draws whose :func:`power` reaches ``target`` (``most`` + 1 if none up to ``most`` does)."""
    for n in range(2, most + 1):
        if power(n, sd, effect, alpha) >= target:
            return n
    return most + 1


def seeds_for_cost(
    components: Mapping, effect: float, draw_minutes: float, seed_minutes: float, alpha: float = 0.05, most: int = 8
) -> list[dict]:
    """For 1 … ``most`` training seeds a draw: the draws for 80% power at ``effect`` and their compute
    (``draw_minutes`` a draw's fixed cost: its split's AutoEncoder, pools, renders; ``seed_minutes`` each seed's
    networks), cheapest first."""
    rows = []
    for s in range(1, most + 1):
        sd = draw_mean_sd(components, s)
        n = draws_for_power(sd, effect, alpha)
        rows.append({"seeds": s, "draw_sd": sd, "draws": n, "hours": n * (draw_minutes + s * seed_minutes) / 60})
    return sorted(rows, key=lambda r: r["hours"])


def simulate_coverage(
    full: np.ndarray,
    resampled: np.ndarray,
    n_draws: int,
    n_seeds: int,
    n_sims: int,
    rng: np.random.Generator,
    level: float = 0.95,
) -> dict:
    """Coverage of :func:`draw_test`'s interval under the confirmatory design, simulated from measured networks.

    Each simulated draw takes one draw of a measured study at random, ``n_seeds`` of its training seeds without
    replacement and a test set of its own (one object resample, never used by another simulated draw): its value is
    the mean over those seeds of the contrast on that test set. The target is the contrast's mean over every
    measured draw and seed on the whole test set, the value the interval claims to cover.

    Parameters
    ----------
    full : (D, S) float — the contrast of measured draw d, seed s on all its test objects
    resampled : (D, S, R) float — the same under R object resamples, R ≥ ``n_sims`` × ``n_draws``
    n_draws, n_seeds : the design simulated
    n_sims : simulated studies

    Returns
    -------
    dict — ``coverage`` (share of the simulated intervals that hold the target), ``mc_se`` (its binomial standard
    error), ``target``, ``mean_half_width``, ``n_sims``, ``n_draws``, ``n_seeds``
    """
    full, resampled = np.asarray(full, dtype=float), np.asarray(resampled, dtype=float)
    n_measured, n_seeds_measured, n_resamples = resampled.shape
    if n_resamples < n_sims * n_draws:
        raise ValueError(f"simulate_coverage: {n_resamples} resamples, need {n_sims * n_draws}")
    target = float(full.mean())
    covered, widths = 0, []
    for i in range(n_sims):
        means = []
        for j in range(n_draws):
            d = rng.integers(n_measured)
            seeds = rng.choice(n_seeds_measured, size=min(n_seeds, n_seeds_measured), replace=False)
            means.append(float(np.nanmean(resampled[d, seeds, i * n_draws + j])))
        t = draw_test(means, level)
        if t["low"] is None:
            continue
        covered += t["low"] <= target <= t["high"]
        widths.append((t["high"] - t["low"]) / 2)
    n = max(len(widths), 1)
    rate = covered / n
    return {
        "coverage": rate,
        "mc_se": float(np.sqrt(rate * (1 - rate) / n)),
        "target": target,
        "mean_half_width": float(np.mean(widths)) if widths else None,
        "n_sims": len(widths),
        "n_draws": n_draws,
        "n_seeds": n_seeds,
    }


def exchange_rate_on_curve(sizes: Sequence[int], curve: np.ndarray, arm: np.ndarray, level: float = 0.95) -> dict:
    """What an arm is worth in real objects, read on the measured real-shape curve only.

    Parameters
    ----------
    sizes : (K,) — the real base sizes of the curve (ascending, e.g. 25, 50, 100, 150, 200); or (D, K), each
        draw's own sizes (e.g. the objects of each base set that hold datapoints): each draw's curve is read on its
        own sizes, and the common grid runs from the largest first size to the smallest last one (every draw measured
        there)
    curve : (D, K) — each draw's mean test AP of the 1:0 network at each size
    arm : (D,) — each draw's mean test AP of the arm (e.g. targeted@50)

    Returns
    -------
    dict — ``worth`` (the real base size whose mean-curve AP equals the arm's mean AP, linearly interpolated; None
    outside the curve, with ``outside`` "below" or "above"), ``low``, ``high`` (the sizes W at which a one-sample
    t over draws of arm − curve(W) is not rejected at ``level``, on a grid inside the curve; None where the interval
    reaches the curve's end: "≤ smallest" or "≥ largest" is all the data say), ``sizes`` (the sizes, rounded, of a
    common curve), ``ends`` (the grid's first and last size)
    """
    curve, arm = np.asarray(curve, dtype=float), np.asarray(arm, dtype=float)
    per_draw = np.broadcast_to(np.asarray(sizes, dtype=float), curve.shape)
    grid = np.linspace(per_draw[:, 0].max(), per_draw[:, -1].min(), 701)
    at = np.stack([np.interp(grid, x, row) for x, row in zip(per_draw, curve)])  # (D, G)
    mean_at, target = at.mean(axis=0), float(arm.mean())
    shown = np.asarray(sizes, dtype=float)
    out = {
        "sizes": [int(round(s)) for s in (shown if shown.ndim == 1 else shown.mean(axis=0))],
        "ends": [float(grid[0]), float(grid[-1])],
        "worth": None,
        "low": None,
        "high": None,
        "outside": None,
    }
    if target < mean_at[0]:
        out["outside"] = "below"
    elif target > mean_at[-1]:
        out["outside"] = "above"
    else:
        out["worth"] = float(grid[np.argmax(mean_at >= target)])  # the first crossing (the curve may not be monotone)
    diffs = arm[:, None] - at  # (D, G)
    if len(arm) >= 2:
        accepted = np.array([_not_rejected(diffs[:, g], level) for g in range(len(grid))])
        if accepted.any():
            first, last = np.flatnonzero(accepted)[[0, -1]]
            out["low"] = None if first == 0 else float(grid[first])
            out["high"] = None if last == len(grid) - 1 else float(grid[last])
            out["accepted_any"] = True
        else:
            out["accepted_any"] = False
    return out


def _not_rejected(values: np.ndarray, level: float) -> bool:
    """Whether the two-sided t at ``level`` does not reject a zero mean of ``values``."""
    t = draw_test(values, level)
    return t["low"] is not None and t["low"] <= 0 <= t["high"]


def nested_draw_test(full: np.ndarray, resampled: np.ndarray, level: float = 0.95) -> dict:
    """A contrast's test over draws on ONE test set that every draw shares (an external set): the interval of
    :func:`~graspaug.experiments.stats.nested_t_interval` (the draws' t part and the objects' bootstrap part, since
    a fixed set of objects is not redrawn with the draws) and the two-sided p that goes with it, the ``1 − level`` at
    which that interval's end reaches 0 (so ``p < 1 − level`` exactly when the interval excludes 0).

    Parameters
    ----------
    full : (D, S) — the contrast of draw d, seed s on all the set's objects
    resampled : (D, S, R) — the same under each of R resamples of the objects (the same resamples in every cell)

    Returns
    -------
    dict — :func:`nested_t_interval`'s keys and ``p`` (None without an interval), ``per_draw`` (the draws' means over
    seeds)
    """
    from scipy.optimize import brentq

    from graspaug.experiments.stats import nested_t_interval, variance_parts

    out = nested_t_interval(full, resampled, level) | {"p": None}
    out["per_draw"] = [float(v) for v in np.asarray(full, dtype=float).mean(axis=1)]
    if out["low"] is None:
        return out
    units, objects = variance_parts(full, resampled)
    objects = objects[np.isfinite(objects)]
    s2, v = units.var(ddof=1) / len(units), objects.var(ddof=1)
    mean = abs(out["mean"])

    def half(lv: float) -> float:
        t, z = stats.t.ppf(0.5 + lv / 2, len(units) - 1), stats.norm.ppf(0.5 + lv / 2)
        return float(np.sqrt(t * t * s2 + z * z * v)) - mean

    lo, hi = 1e-12, 1 - 1e-12
    if half(lo) >= 0:
        p = 1.0
    elif half(hi) <= 0:
        p = 1e-12
    else:
        p = 1.0 - brentq(half, lo, hi, xtol=1e-14)
    return out | {"p": float(p)}


def per_object_ap(labels: np.ndarray, objects: np.ndarray, scores: np.ndarray) -> pd.Series:
    """Each object's own AP (object → AP) over the objects that hold at least one positive datapoint."""
    from graspaug.experiments.stats import weighted_average_precision

    frame = pd.DataFrame({"label": np.asarray(labels, dtype=bool), "object": objects, "score": scores})
    out = {}
    for name, rows in frame.groupby("object", sort=True):
        if rows.label.any():
            y, p = rows.label.to_numpy(), rows.score.to_numpy()
            out[name] = float(weighted_average_precision(y, p, np.ones(len(rows))))
    return pd.Series(out, dtype=float)


def network_values(labels, objects, scores, n_resamples: int, seed: int) -> dict[str, tuple[float, np.ndarray]]:
    """One network's two readouts, each (value on every object, (n_resamples,) values under the objects' resamples):
    the same resamples for every network (the same ``seed``), so differences are paired."""
    from graspaug.experiments.stats import ObjectBootstrap, weighted_average_precision

    boot = ObjectBootstrap(objects, n_resamples, seed)
    ones = np.ones(len(labels), dtype=np.float32)
    pooled = (float(weighted_average_precision(labels, scores, ones)), boot.average_precision(labels, scores))
    aps = per_object_ap(labels, objects, scores)
    held = ObjectBootstrap(aps.index.to_numpy(), n_resamples, seed)
    per_object = (float(aps.mean()), held.means(aps.to_numpy()))
    return {"pooled": pooled, "per_object": per_object}
