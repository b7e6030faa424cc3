"""The cell's numbers: success rates, the declared paired contrasts (bootstrap over objects, t-interval over seeds),
the setup, and the networks' ranking of the calibration grasps' outcomes (ROC AUC, paired over seeds)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np
import pandas as pd

from graspaug.errors import DataError
from graspaug.experiments.ap.numbers import test_predictions, test_rows
from graspaug.experiments.cell.picks import ANTIPODAL, ORACLE, feasible_rows, oracle_readout
from graspaug.experiments.stats import (
    DIFFERENCE_RANGE,
    ObjectBootstrap,
    contrast,
    headline,
    paired_contrast,
    percentile_interval,
    t_interval,
    weighted_roc_auc,
    wilson_interval,
)
from graspaug.rng import shape_rng

#: The contrasts of the sim metrics: name → (arm, reference arm); success(arm) − success(reference).
CONTRASTS = {
    "real_data": ("more_real", "before"),  # the positive control: more real training shapes, no augmentation
    "after_vs_before": ("after", "before"),
    "network_vs_antipodal": ("before", "antipodal"),
    "after_vs_real": ("after", "real"),
    "oracle_vs_antipodal": (ORACLE, ANTIPODAL),  # the cell's span: the ceiling (mesh oracle) − the floor
}


def rate_summary(outcomes: pd.Series) -> dict:
    """Successes, attempts, the rate and its 95 % Wilson interval of boolean ``outcomes``."""
    k, n = int(outcomes.sum()), int(len(outcomes))
    low, high = wilson_interval(k, n)
    return {
        "successes": k,
        "attempts": n,
        "success_rate": round(k / n, 5) if n else None,
        "wilson_low": round(low, 5),
        "wilson_high": round(high, 5),
    }


def paired_outcomes(trials: pd.DataFrame, arm: str, reference: str) -> pd.DataFrame:
    """One row per paired attempt: ``seed``, ``object``, ``attempt``, ``a`` and ``b`` (success of
    ``arm`` and ``reference``); an arm run once (seed −1) pairs with every seed of the other."""
    columns = ["seed", "object", "attempt", "success"]
    a = trials.loc[trials.arm == arm, columns].rename(columns={"success": "a"})
    b = trials.loc[trials.arm == reference, columns].rename(columns={"success": "b"})
    keys = ["seed", "object", "attempt"]
    if set(b.seed) == {-1}:
        b, keys = b.drop(columns="seed"), ["object", "attempt"]
    elif set(a.seed) == {-1}:
        a, keys = a.drop(columns="seed"), ["object", "attempt"]
    if a.empty or b.empty:
        raise DataError(f"sim: arm {arm if a.empty else reference!r} has no attempts; the arms cannot be paired")
    paired = a.merge(b, on=keys, how="outer")
    lonely = paired[paired[["a", "b"]].isna().any(axis=1)]
    if len(lonely):
        first = ", ".join(f"{k} {lonely.iloc[0][k]}" for k in keys)
        raise DataError(
            f"sim: {len(lonely)} attempts of {arm!r} or {reference!r} have no partner (first: {first}); "
            "the arms cannot be paired"
        )
    return paired.assign(a=paired.a.astype(bool), b=paired.b.astype(bool))


def trial_contrast(trials: pd.DataFrame, arm: str, reference: str, n_boot: int = 2000, seed: int = 0) -> dict:
    """success(arm) − success(reference) on the paired attempts: ``mean``; the 95 % bootstrap
    interval over objects (``objects_low``, ``objects_high``; each resampled object brings all its
    attempts; the verdict's); ``n_trials`` (paired drops), ``n_objects``; the 95 % t-interval over training
    seeds of the per-seed differences (``seeds_low``, ``seeds_high``, ``n_seeds``, ``per_seed``);
    and, when both arms ran once per training seed, the discordant counts (``only_<arm>``,
    ``only_<reference>``). No McNemar test: the picks cluster by object and seed, so they are not
    independent pairs; the two intervals above are the inference.

    An arm without a network (seed −1) ran each drop once: the other arm's outcomes of that
    drop are averaged over the training seeds first, so a drop counts once (its differences
    are then not 0/1, and the counts are None)."""
    paired = paired_outcomes(trials, arm, reference)
    per_seed = paired.groupby("seed").apply(lambda d: float(d.a.mean() - d.b.mean()), include_groups=False)
    over_seeds = t_interval(per_seed.to_numpy(), bounds=DIFFERENCE_RANGE)  # none past [-1, 1]: too few seeds
    once = -1 in set(trials.seed[trials.arm.isin([arm, reference])])
    if once:
        drops = paired.groupby(["object", "attempt"], sort=False).agg(a=("a", "mean"), b=("b", "mean")).reset_index()
        a, b, objects = drops.a.to_numpy(float), drops.b.to_numpy(float), drops.object.to_numpy()
        counts = {f"only_{arm}": None, f"only_{reference}": None}
    else:
        a, b, objects = paired.a.to_numpy(float), paired.b.to_numpy(float), paired.object.to_numpy()
        counts = {
            f"only_{arm}": int((paired.a & ~paired.b).sum()),
            f"only_{reference}": int((paired.b & ~paired.a).sum()),
        }
    difference = paired_contrast(a, b, ObjectBootstrap(objects, n_boot, seed))
    rounded = lambda x: None if x is None else round(float(x), 5)  # noqa: E731
    return contrast(
        rounded(difference["mean"]),
        "objects",
        over_seeds["n_seeds"],
        objects=(rounded(difference["objects_low"]), rounded(difference["objects_high"])),
        seeds=(rounded(over_seeds["low"]), rounded(over_seeds["high"])),
        n_trials=int(len(a)),
        n_objects=int(len(set(objects))),
        per_seed={str(k): round(v, 5) for k, v in per_seed.items()},
        **counts,
    )


def compare(trials: pd.DataFrame) -> dict:
    """Before vs after on the attempts of ``trials``: both rates, the difference, and the discordant
    counts of the attempts paired by seed, object and drop (``paired``: ``only_before``, ``only_after``)."""
    out = {arm: rate_summary(trials.success[trials.arm == arm]) for arm in ("before", "after")}
    paired = paired_outcomes(trials, "after", "before")
    out["difference"] = round(out["after"]["success_rate"] - out["before"]["success_rate"], 5)
    out["paired"] = {"only_before": int((paired.b & ~paired.a).sum()), "only_after": int((paired.a & ~paired.b).sum())}
    return out


def calibration(trials: pd.DataFrame, graspness: pd.Series) -> tuple[pd.DataFrame, dict]:
    """Per object: the antipodal arm's success rate beside its labels' ``graspness`` (a Series by
    object name; objects without labels get NaN), and their Spearman correlation over the
    objects with labels (None with fewer than 3)."""
    from scipy.stats import spearmanr

    antipodal = trials[trials.arm == "antipodal"]
    table = antipodal.groupby("object", sort=False).agg(
        kind=("kind", "first"), attempts=("success", "size"), sim_success=("success", "mean")
    )
    table["graspness"] = graspness.reindex(table.index).to_numpy(float)
    labelled = table.dropna(subset=["graspness"])
    summary = {"n_objects": int(len(labelled)), "spearman": None, "p_value": None}
    if len(labelled) >= 3 and labelled.sim_success.nunique() > 1 and labelled.graspness.nunique() > 1:
        result = spearmanr(labelled.sim_success, labelled.graspness)
        summary["spearman"], summary["p_value"] = round(float(result.statistic), 4), round(float(result.pvalue), 5)
    return table.reset_index(), summary


def trial_setup(
    sim, objects: Sequence, skipped: dict[str, str], model_seeds: list[int], after_from_report: bool, data_seed: int
) -> dict:
    """The metrics' ``setup``: base size, whether the ``after`` ratio came from the AP report, the
    object count and attempts per object, the test shapes and user objects among ``objects``, the
    user's meshes skipped (file → why), camera height (m), sensor noise on or off, training seeds,
    the draw of the data the networks were trained on (``data_seed``).
    ``sim``: the ``sim`` params section (``SimParams``)."""
    return {
        "base_size": sim.base_size,
        "after_ratio_from_report": after_from_report,
        "objects": len(objects),
        "attempts": sim.attempts,
        "test_shapes": [o.name for o in objects if o.kind == "test_shape"],
        "user_objects": [o.name for o in objects if o.kind == "user"],
        "skipped_meshes": skipped,
        "camera_height": sim.cell.camera_height,
        "sensor_noise": sim.sensor.enabled,
        "grip_force": sim.hand.grip_force,
        "shake_acceleration": sim.trial.shake_acceleration,
        "model_seeds": model_seeds,
        "data_seed": data_seed,
    }


def summarize(trials: pd.DataFrame, objects: Sequence, chosen: dict, setup: dict, n_boot: int, seed: int) -> dict:
    """The experiment's report (its metrics: :func:`sim_headline`): setup, per-arm rates (Wilson), the
    contrasts (paired, bootstrap over objects), before vs after per training seed, per-object rates. ``objects``: the
    :class:`~graspaug.experiments.cell.trials.PreparedObject` of the trials; ``chosen``: arm → (pool, ratio,
    base size)."""
    model_seeds = setup["model_seeds"]
    metrics = {
        "setup": setup,
        "arms": {
            arm: {"pool": pool, "ratio": ratio, "base_size": b, **rate_summary(trials.success[trials.arm == arm])}
            for arm, (pool, ratio, b) in chosen.items()
        },
        "contrasts": {
            name: trial_contrast(trials, arm, ref, n_boot, seed)
            for name, (arm, ref) in CONTRASTS.items()
            if arm in chosen and ref in chosen
        },
        "same_network": chosen["before"] == chosen["after"],
        "per_seed": {str(s): compare(trials[trials.seed == s]) for s in model_seeds},
        "per_object": {},
    }
    feasible = trials.groupby("object").feasible.first() if "feasible" in trials else None
    for obj in objects:
        sel = trials.object == obj.name
        rates = {arm: rate_summary(trials.success[sel & (trials.arm == arm)]) for arm in chosen}
        metrics["per_object"][obj.name] = {
            "kind": obj.kind,
            "mass": round(obj.body.mass, 4),
            "friction": round(obj.body.lateral_friction, 4),
            **({} if feasible is None else {"feasible": bool(feasible[obj.name])}),
            **rates,
        }
    if feasible is not None:
        metrics["feasibility"] = feasible_first(trials, list(chosen))
    return metrics


def feasible_first(trials: pd.DataFrame, arms: Sequence[str]) -> dict:
    """Success on the feasible objects (:func:`~graspaug.experiments.cell.picks.feasible_rows`: the feasibility
    rule's, from geometry before any pick) and on all objects: for each (``feasible``, ``all``) the count of objects,
    every arm's rate (:func:`rate_summary`) and its share of the oracle − antipodal span where defined; with the
    oracle's rate on the feasible attempts and whether it makes the cell fit to compare planners
    (:func:`~graspaug.experiments.cell.picks.oracle_readout`; both None without a feasible object)."""
    out = {}
    for name, sel in (("feasible", feasible_rows(trials)), ("all", pd.Series(True, index=trials.index))):
        n_objects = int(trials.object[sel].nunique())
        rates = {arm: rate_summary(trials.success[sel & (trials.arm == arm)]) for arm in arms} if n_objects else {}
        readout = oracle_readout({arm: r["successes"] / r["attempts"] for arm, r in rates.items()})  # not rounded
        shares = {a: round(v, 5) for a, v in readout["span_share"].items()}
        out[name] = {"objects": n_objects, "arms": rates, "span_share": shares}
        if name == "feasible":
            out["oracle_rate"], out["oracle_fit"] = readout["oracle_rate"], readout["oracle_fit"]
    return out


def sim_headline(summary: dict) -> dict[str, dict]:
    """The experiment's metrics from its :func:`summarize` report: per contrast the mean paired success
    difference and its 95% bootstrap interval over objects (:func:`~graspaug.experiments.stats.headline`),
    and, as ``ranking_<contrast>``, the paired difference in ROC AUC against the cell's outcomes of the
    executed calibration grasps (``summary["ranking"]``, :func:`graspaug.experiments.cell.numbers.cell_ranking`)."""
    ranking = (summary.get("ranking") or {}).get("contrasts", {})
    return {
        **{name: headline(c) for name, c in summary["contrasts"].items()},
        **{f"ranking_{name}": headline(c) for name, c in ranking.items()},
    }


def objects_table(objects: Sequence) -> pd.DataFrame:
    """One row per object (:class:`~graspaug.experiments.cell.trials.PreparedObject`): name, kind, extents (m),
    density (kg/m³), mass (kg), friction, the convex hulls of its collision file and that file's name."""
    return pd.DataFrame(
        [
            {
                "object": o.name,
                "kind": o.kind,
                "extent_x": o.extents[0],
                "extent_y": o.extents[1],
                "extent_z": o.extents[2],
                "density": round(o.density, 1),
                "mass": o.body.mass,
                "friction": o.body.lateral_friction,
                "convex_hulls": ("\n" + o.body.collision.read_text()).count("\no "),
                "collision_file": o.body.collision.name,
            }
            for o in objects
        ]
    )


def success_table(metrics: dict, arms: Sequence[str]) -> pd.DataFrame:
    """Success rate per object (rows) and arm (columns) of the :func:`summarize` metrics."""
    return pd.DataFrame(
        [
            {"object": name, **{arm: row[arm]["success_rate"] for arm in arms}}
            for name, row in metrics["per_object"].items()
        ]
    )


def planning_timing(trials: pd.DataFrame, arms: list[str]) -> dict:
    """Planning time per grasp (s): mean, median, max over the trials, mean per arm; the stage
    fills in ``stage_seconds``."""
    planning = trials.planning_time.dropna()

    def mean(values: pd.Series) -> float | None:
        values = values.dropna()
        return float(values.mean()) if len(values) else None

    return {
        "planning_time_mean": mean(planning),
        "planning_time_median": float(planning.median()) if len(planning) else None,
        "planning_time_max": float(planning.max()) if len(planning) else None,
        "planning_time_by_arm": {arm: mean(trials.planning_time[trials.arm == arm]) for arm in arms},
        "trials": int(len(trials)),
        "stage_seconds": None,
    }


def arm_scores(grasps: pd.DataFrame, seed_dirs: Mapping[int, Path], chosen: Mapping) -> dict[str, np.ndarray]:
    """Each arm's P(success) on the executed grasps: arm → (S, G) for the S training seeds of
    ``seed_dirs`` (seed → folder of its networks) and the G rows of ``grasps`` (the calibration
    table, its ``datapoint`` column: the row in the rendered dataset's index). ``chosen``: arm →
    (pool, ratio, base size), as :func:`graspaug.experiments.cell.trials.arms` gives; arms without a
    network are left out. Raises DataError when a datapoint is not among a seed's test rows."""
    where = {}  # seed → each grasp's position among the seed's test predictions
    for seed, seed_dir in seed_dirs.items():
        where[seed] = pd.Index(test_rows(seed_dir)).get_indexer(grasps.datapoint.to_numpy())
        if (where[seed] < 0).any():
            raise DataError(
                f"sim: {int((where[seed] < 0).sum())} executed calibration grasps are not test datapoints of seed "
                f"{seed} ({seed_dir}): rerun `dvc repro grasp_calibration`"
            )
    scores = {}
    for arm, (pool, ratio, base_size) in chosen.items():
        if pool is not None:
            scores[arm] = np.stack(
                [test_predictions(seed_dir, (pool, base_size, ratio))[where[s]] for s, seed_dir in seed_dirs.items()]
            )
    return scores


def cell_ranking(grasps: pd.DataFrame, seed_dirs: Mapping[int, Path], chosen: Mapping, n_boot: int, seed: int) -> dict:
    """ROC AUC of each arm's network against the cell's outcomes (``executed_success``) of the
    executed calibration ``grasps`` (:func:`arm_scores`), and the paired contrasts between arms.

    Returns ``{"n_grasps", "n_objects", "reference": {"eps", "label"}, "arms": {arm: {"auc", "per_seed",
    "auc_label"}}, "contrasts": {name: {...}}}``: ``auc`` the mean over training seeds (``auc_label``:
    the same networks' ROC AUC against the grasps' labels instead; None when the grasps hold one label
    only); a contrast's ``mean`` is the mean over seeds of the AUC difference, ``objects_low``, ``objects_high``
    its 95 % bootstrap interval over the grasps' objects (shapes; one resample for every network),
    ``seeds_low``, ``seeds_high`` the t-interval over seeds, ``per_seed``. The robust ε and the label,
    scored the same way, are the reference. When every grasp had the same outcome there is nothing to
    rank: no arms, no contrasts, reference None."""
    y = grasps.executed_success.to_numpy(bool)
    counts = {"n_grasps": int(len(grasps)), "n_objects": int(grasps.shape_id.nunique())}
    if len(np.unique(y)) < 2:  # every grasp held, or none: nothing to rank
        return {**counts, "reference": None, "arms": {}, "contrasts": {}}
    scores = arm_scores(grasps, seed_dirs, chosen)
    full, resampled = auc_samples(y, scores, ranking_bootstrap(grasps, n_boot, seed))
    return {**counts, **ranking_summary(grasps, list(seed_dirs), scores, full, resampled)}


def ranking_summary(grasps: pd.DataFrame, seeds: list, scores: dict, full: dict, resampled: dict) -> dict:
    """The ``reference``, ``arms`` and ``contrasts`` of :func:`cell_ranking` from the arms' ``scores``
    (:func:`arm_scores`) and their AUCs ``full``, ``resampled`` (:func:`auc_samples`) for the training
    ``seeds`` in that order."""
    y, label = grasps.executed_success.to_numpy(bool), grasps.label.to_numpy(bool)
    seeds = [str(s) for s in seeds]
    rounded = lambda x: None if x is None or not np.isfinite(x) else round(float(x), 5)  # noqa: E731
    contrasts = {}
    for name, (arm, reference) in CONTRASTS.items():
        if arm not in full or reference not in full:
            continue
        per_seed = full[arm] - full[reference]
        lo, hi = percentile_interval((resampled[arm] - resampled[reference]).mean(axis=0))
        over_seeds = t_interval(per_seed, bounds=DIFFERENCE_RANGE)  # none past [-1, 1]: too few seeds
        contrasts[name] = contrast(
            rounded(per_seed.mean()),
            "objects",
            over_seeds["n_seeds"],
            objects=(rounded(lo), rounded(hi)),
            seeds=(rounded(over_seeds["low"]), rounded(over_seeds["high"])),
            per_seed=dict(zip(seeds, map(rounded, per_seed))),
        )
    return {
        "reference": {k: rounded(boot_auc(y, grasps[k].to_numpy(float), None)) for k in ("eps", "label")},
        "arms": {
            arm: {
                "auc": rounded(auc.mean()),
                "per_seed": dict(zip(seeds, map(rounded, auc))),
                "auc_label": rounded(np.mean([boot_auc(label, s, None) for s in scores[arm]])),
            }
            for arm, auc in full.items()
        },
        "contrasts": contrasts,
    }


def ranking_bootstrap(grasps: pd.DataFrame, n_boot: int, seed: int) -> ObjectBootstrap:
    """The resamples of the executed ``grasps``' shapes that every network's AUC is computed under."""
    return ObjectBootstrap(grasps.shape_id.to_numpy(), n_boot, shape_rng(seed, "sim", "ranking-bootstrap"))


def auc_samples(y: np.ndarray, scores: Mapping[str, np.ndarray], boot: ObjectBootstrap):
    """Each arm's ROC AUC against the outcomes ``y`` (G,) of its ``scores`` (arm → (S, G), :func:`arm_scores`):
    (arm → (S,) on all grasps, arm → (S, R) under the R resamples of ``boot``), one value per training seed."""
    full = {arm: np.array([boot_auc(y, s, None) for s in rows]) for arm, rows in scores.items()}
    return full, {arm: np.stack([boot_auc(y, s, boot) for s in rows]) for arm, rows in scores.items()}


def boot_auc(y: np.ndarray, score: np.ndarray, boot: ObjectBootstrap | None):
    """ROC AUC of ``score`` for ``y`` on all grasps (``boot`` None: a float) or under every
    resample of ``boot`` ((R,))."""
    if boot is None:
        return float(weighted_roc_auc(y, score, np.ones(len(y))))
    return boot.roc_auc(y, score)
