"""The paper's robot experiment on real objects (issue #76): success rates of picks by arm, their paired contrasts
and the objects behind them, from a table of attempts.

The attempts table (``results/real-picks/attempts.parquet``) holds one row per attempt: ``draw``, ``seed``, ``arm``,
``object``, ``attempt``, ``drop_seed``, ``success`` (bool), ``outcome``, ``quality`` (the network's P(success), NaN
for the antipodal arm) and the executed grasp (``grasp_x``, ``grasp_y``, ``grasp_z`` m, ``jaw_angle`` rad).
Attempts of one object are not independent (one shape, one network): the unit is the object. Within a draw, an
arm's rate is the mean over its test objects of each object's share of successful attempts; a paired contrast is
the mean over objects of the difference of two arms' shares (the same drops in every arm). Over several draws (each
with its own test objects) the interval is a t over the draws' values, which carries the objects' variance; with one
draw it is the objects' bootstrap (attempts resampled with their object).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence

import numpy as np
import pandas as pd

from graspaug.experiments.confirm.numbers import draw_test
from graspaug.experiments.stats import ObjectBootstrap, percentile_interval

ANTIPODAL = "antipodal"
#: The arm that picks with the best grasp on the true mesh in the dropped pose (graspaug.sim.oracle.MeshOracle).
ORACLE = "oracle"
#: The paper's robot result (Section IV-D): 8 everyday objects, 10 attempts each, no interval.
PAPER = {"objects": 8, "attempts": 10, "before": 0.68, "after": 0.86}


def object_rates(attempts: pd.DataFrame) -> pd.DataFrame:
    """Each (draw, arm, object)'s share of successful attempts: a table indexed by (draw, object), a column per arm."""
    rates = attempts.groupby(["draw", "arm", "object"]).success.mean().unstack("arm")
    return rates.sort_index()


def _interval(values_by_draw: dict[int, np.ndarray], n_resamples: int, seed: int) -> dict:
    """Mean and 95% interval of a per-object quantity: t over the draws' means with two draws or more, else the
    objects' bootstrap of the one draw."""
    means = [float(np.mean(v)) for v in values_by_draw.values()]
    if len(values_by_draw) >= 2:
        return _over_draws(means)
    (values,) = values_by_draw.values()
    boot = ObjectBootstrap(np.arange(len(values)), n_resamples, seed)
    return _over_objects(means[0], boot.means(np.asarray(values, dtype=float)), len(values))


def _over_draws(per_draw: list[float]) -> dict:
    """A quantity's mean and 95% t-interval over its per-draw values (:func:`draw_test`)."""
    t = draw_test(per_draw)
    out = {"mean": t["mean"], "low": t["low"], "high": t["high"], "p": t["p"], "over": "draws", "n": len(per_draw)}
    return out | {"per_draw": t["per_draw"]}


#: The fewest objects an objects' bootstrap gives an interval over: below it, resampling a handful of objects gives a
#: few distinct values (two objects: three), and a percentile of them is no interval.
MIN_OBJECTS = 5


def _over_objects(mean: float, resampled: np.ndarray, n_objects: int) -> dict:
    """A one-draw quantity's ``mean`` and the percentile interval of its objects' bootstrap ``resampled`` (R,); no
    interval over fewer than :data:`MIN_OBJECTS` objects, and ``why`` says so."""
    out = {"mean": mean, "low": None, "high": None, "p": None, "over": "objects", "n": int(n_objects)}
    if n_objects < MIN_OBJECTS:
        return out | {"why": f"no interval: {n_objects} objects (an objects' bootstrap needs {MIN_OBJECTS} or more)"}
    low, high = percentile_interval(resampled)
    return out | {"low": low, "high": high}


def _control_arm(arms: Sequence[str]) -> str:
    """The positive control's arm: the largest none@B above 50 (none@150 in the confirmatory study)."""
    return max((a for a in arms if a.startswith("none@") and a != "none@50"), default="none@150", key=_size)


def pick_summary(attempts: pd.DataFrame, arms: Sequence[str], n_resamples: int = 2000, seed: int = 0) -> dict:
    """Rates by arm, the contrasts (``control``: none@B − none@50, B the largest none arm, 150 in the confirmatory
    study; ``targeted_vs_none``: targeted@50 − none@50;
    ``<arm>_vs_antipodal``) and their verdicts, the control read first: where it does not show, every other verdict
    is "the cell cannot tell"."""
    rates = object_rates(attempts)
    missing = [a for a in arms if a not in rates]
    if missing:
        raise ValueError(f"no attempts of arm(s) {missing}")
    by_draw = {int(d): g.droplevel("draw") for d, g in rates.groupby(level="draw")}
    out = {"arms": {}, "contrasts": {}, "draws": sorted(by_draw), "objects": int(len(rates))}
    out["attempts_per_arm"] = {a: int((attempts.arm == a).sum()) for a in arms}
    for arm in arms:
        out["arms"][arm] = _interval({d: g[arm].to_numpy() for d, g in by_draw.items()}, n_resamples, seed)
    pairs = {"control": (_control_arm(arms), "none@50"), "targeted_vs_none": ("targeted@50", "none@50")}
    pairs |= {f"{a}_vs_antipodal": (a, ANTIPODAL) for a in arms if a != ANTIPODAL}
    for name, (a, b) in pairs.items():
        if a in arms and b in arms:
            diffs = {d: (g[a] - g[b]).to_numpy() for d, g in by_draw.items()}
            out["contrasts"][name] = _interval(diffs, n_resamples, seed) | {"a": a, "b": b}
    _read_control_first(out)
    ranking = pick_ranking(attempts, n_resamples, seed)
    if ranking:
        out["ranking"] = ranking
    return out


def pick_ranking(attempts: pd.DataFrame, n_resamples: int = 2000, seed: int = 0) -> dict:
    """Each network's ranking of the cell's outcomes: the ROC AUC of its success probability (``score_<arm>``)
    against the outcome of every executed grasp of the draw (every arm's attempts that planned one, the antipodal
    arm's too, so every network scores the same grasps), and the paired AUC differences ``control`` and
    ``targeted_vs_none`` (control first, as :func:`pick_summary`). A ranking needs fewer attempts than a rate: it
    uses every executed grasp, not only each network's own best. Intervals: t over the draws' AUCs with two draws
    or more, else the objects' bootstrap of the one draw. ``{}`` where the table holds no scores."""
    from graspaug.experiments.stats import weighted_roc_auc

    arms = [c.removeprefix("score_") for c in attempts.columns if c.startswith("score_")]
    if not arms:
        return {}
    executed = attempts.dropna(subset=[f"score_{a}" for a in arms])
    by_draw = {int(d): g for d, g in executed.groupby("draw") if g.success.nunique() == 2}
    if not by_draw:
        return {"grasps": int(len(executed)), "arms": {}, "contrasts": {}, "control_shows": False}

    def auc(g: pd.DataFrame, arm: str) -> float:
        return float(weighted_roc_auc(g.success.to_numpy(bool), g[f"score_{arm}"].to_numpy(float), np.ones(len(g))))

    def interval(
        values: Callable[[pd.DataFrame], float], boot_values: Callable[[pd.DataFrame, ObjectBootstrap], np.ndarray]
    ) -> dict:
        if len(by_draw) >= 2:
            return _over_draws([values(g) for g in by_draw.values()])
        (g,) = by_draw.values()
        boot = ObjectBootstrap(g.object.to_numpy(), n_resamples, seed)
        return _over_objects(values(g), boot_values(g, boot), g.object.nunique())

    def boot_auc(g: pd.DataFrame, boot: ObjectBootstrap, arm: str) -> np.ndarray:
        return boot.roc_auc(g.success.to_numpy(bool), g[f"score_{arm}"].to_numpy(float))

    out = {"grasps": int(sum(len(g) for g in by_draw.values())), "draws": sorted(by_draw), "arms": {}, "contrasts": {}}
    for arm in arms:
        out["arms"][arm] = interval(lambda g, a=arm: auc(g, a), lambda g, b, a=arm: boot_auc(g, b, a))
    for name, (a, b) in {
        "control": (_control_arm(arms), "none@50"),
        "targeted_vs_none": ("targeted@50", "none@50"),
    }.items():
        if a in arms and b in arms:
            c = interval(
                lambda g, a=a, b=b: auc(g, a) - auc(g, b),
                lambda g, bt, a=a, b=b: boot_auc(g, bt, a) - boot_auc(g, bt, b),
            )
            out["contrasts"][name] = c | {"a": a, "b": b}
    _read_control_first(out)
    return out


def _read_control_first(out: dict) -> None:
    """Each contrast's verdict, the control's first: where it does not show, every other is "the cell cannot tell"."""
    control = out["contrasts"].get("control")
    shows = control is not None and control["low"] is not None and control["low"] > 0
    out["control_shows"] = shows
    for name, c in out["contrasts"].items():
        if name == "control" or shows:
            c["verdict"] = _verdict(c)
        else:
            c["verdict"] = "the cell cannot tell (the positive control does not show)"


def _size(arm: str) -> int:
    return int(arm.split("@")[1])


def _verdict(c: dict) -> str:
    if c["low"] is None:
        return c.get("why", "no interval")
    if c["low"] > 0:
        return "higher"
    if c["high"] < 0:
        return "lower"
    return "not shown (the interval holds zero)"


def hardest_objects(attempts: pd.DataFrame, k: int = 10) -> pd.DataFrame:
    """The ``k`` objects with the lowest success over every arm and attempt: their success share by arm."""
    rates = attempts.groupby(["object", "arm"]).success.mean().unstack("arm")
    return rates.loc[rates.mean(axis=1).sort_values(kind="stable").index[:k]]


def never_held(attempts: pd.DataFrame) -> list[str]:
    """Objects that no arm ever held (reported, not dropped)."""
    held = attempts.groupby("object").success.any()
    return sorted(held.index[~held])


def paper_table(summary: dict, before: str = "none@50", after: str = "targeted@50") -> pd.DataFrame:
    """The paper's robot result beside ours: objects, attempts, before, after (rates with their intervals)."""

    def text(c: dict) -> str:
        if c["low"] is None:
            return f"{c['mean']:.0%}"
        return f"{c['mean']:.0%} [{c['low']:.0%}, {c['high']:.0%}]"

    ours = {
        "objects": summary["objects"],
        "attempts": summary["attempts_per_arm"][before] // max(summary["objects"], 1),
        "before": text(summary["arms"][before]),
        "after": text(summary["arms"][after]),
    }
    paper = {k: (f"{v:.0%}" if isinstance(v, float) else v) for k, v in PAPER.items()}
    return pd.DataFrame([paper | {"who": "paper (8 everyday objects, no interval)"}, ours | {"who": "graspaug"}])


def pick_power(attempts: pd.DataFrame, a: str, b: str, n_objects: int, draws: Sequence[int], effect: float) -> dict:
    """The power of the paired contrast ``a`` − ``b`` (two arms) over draws of ``n_objects`` test objects each, from a
    pilot's attempts: the SD of the per-object difference of success shares, so one draw's value has SD
    ``sd / √n_objects`` (the draws' own spread beyond their objects is not in a one-draw pilot: the power is an upper
    bound), against a true difference ``effect``; the power of the t over ``draws`` draws for each count."""
    from graspaug.experiments.confirm.numbers import power

    rates = object_rates(attempts)
    diffs = (rates[a] - rates[b]).to_numpy()
    sd = float(np.std(diffs, ddof=1))
    per_draw = sd / np.sqrt(n_objects)
    return {
        "pilot_objects": int(len(diffs)),
        "pilot_mean": float(np.mean(diffs)),
        "object_sd": sd,
        "draw_sd": per_draw,
        "effect": effect,
        "power": {int(d): power(int(d), per_draw, effect) for d in draws},
    }


#: The oracle's pick rate on feasible attempts below which the cell is not fit to compare planners (issue #83).
ORACLE_FIT = 0.90


def feasible_rows(table: pd.DataFrame) -> pd.Series:
    """Which rows of a table of picks (attempts or trials) are on objects declared feasible from geometry before any
    pick (its ``feasible`` column; a missing value is not feasible). All False where the table has no such column."""
    if "feasible" not in table:
        return pd.Series(False, index=table.index)
    return table.feasible.astype("boolean").fillna(False).astype(bool)


def oracle_readout(rates: Mapping[str, float]) -> dict:
    """What the ceiling and floor say of the cell, from each arm's success rate on the feasible objects (``rates``,
    arm → rate): ``oracle_rate`` and ``oracle_fit`` (:func:`oracle_fit`; both None without an oracle arm) and
    ``span_share``, each arm's share of the oracle − antipodal span (:func:`span_shares`; ``{}`` where undefined).
    The one reading of the oracle for the sim stage's report and the real-object picks."""
    oracle = rates.get(ORACLE)
    return {
        "oracle_rate": oracle,
        "oracle_fit": None if oracle is None else oracle_fit(oracle),
        "span_share": span_shares(rates),
    }


def feasible_summary(table: pd.DataFrame, n_resamples: int, seed: int) -> dict:
    """The picks on feasible objects (:func:`feasible_rows`): counts of feasible and all object-draws,
    :func:`pick_summary` of the feasible attempts and :func:`oracle_readout` of its rates. ``{}`` where the table has
    no feasible attempt."""
    rows = feasible_rows(table)
    if not rows.any():
        return {}
    feasible = table[rows]
    out = {
        "object_draws": int(len(feasible[["draw", "object"]].drop_duplicates())),
        "all_object_draws": int(len(table[["draw", "object"]].drop_duplicates())),
        "attempts": int(len(feasible)),
    }
    out["summary"] = pick_summary(feasible, list(dict.fromkeys(feasible.arm)), n_resamples, seed)
    readout = oracle_readout({a: c["mean"] for a, c in out["summary"]["arms"].items()})
    return out | {k: v for k, v in readout.items() if v not in (None, {})}


def oracle_fit(rate: float) -> bool:
    """Whether the cell is fit to compare planners: the oracle picks at least :data:`ORACLE_FIT` of the feasible
    attempts (``rate``)."""
    return bool(rate >= ORACLE_FIT)


def span_shares(rates: Mapping[str, float]) -> dict[str, float]:
    """Each arm's share of the oracle − antipodal span, (rate − antipodal) / (oracle − antipodal), from ``rates``
    (arm → success rate); ``{}`` where the span is not defined (no oracle or no antipodal arm, or the oracle does not
    pick more often than the antipodal floor)."""
    if ORACLE not in rates or ANTIPODAL not in rates or not rates[ORACLE] > rates[ANTIPODAL]:
        return {}
    floor, span = rates[ANTIPODAL], rates[ORACLE] - rates[ANTIPODAL]
    return {a: (r - floor) / span for a, r in rates.items()}
