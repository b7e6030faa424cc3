"""What the simulated trials show (:mod:`graspaug.experiments.sim`): success rates with Wilson
intervals, paired contrasts between arms with a bootstrap interval over objects, the calibration
of the cell against the labels' graspness, the metrics, the tables and the report's text.

A trials table has a row per attempt: ``arm``, ``seed`` (the network's training seed; −1 for the
``antipodal`` arm, which has no network and runs once), ``object``, ``kind``, ``attempt``,
``outcome``, ``success``. Attempts pair up by (seed, object, attempt): every arm sees the same
drops and planner seeds; the antipodal arm's attempt pairs with that attempt of every seed.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pandas as pd

from graspaug.errors import DataError
from graspaug.experiments.stats import (
    ObjectBootstrap,
    draw_scope,
    draw_verdict,
    headline,
    paired_contrast,
    t_interval,
    wilson_interval,
)

#: The contrasts of the sim metrics: name → (arm, reference arm); success(arm) − success(reference).
CONTRASTS = {
    "real_data": ("more_real", "before"),  # the positive control: more real training shapes, no augmentation
    "after_vs_before": ("after", "before"),
    "network_vs_antipodal": ("before", "antipodal"),
    "after_vs_real": ("after", "real"),
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
    interval over objects (``ci_low``, ``ci_high``; each resampled object brings all its
    attempts); ``n_trials`` (paired drops), ``n_objects``; the 95 % t-interval over training
    seeds of the per-seed differences (``t_ci_low``, ``t_ci_high``, ``n_seeds``, ``per_seed``);
    and, when both arms ran once per training seed, the discordant counts (``only_<arm>``,
    ``only_<reference>``). No McNemar test: the picks cluster by object and seed, so they are not
    independent pairs; the two intervals above are the inference.

    An arm without a network (seed −1) ran each drop once: the other arm's outcomes of that
    drop are averaged over the training seeds first, so a drop counts once (its differences
    are then not 0/1, and the counts are None)."""
    paired = paired_outcomes(trials, arm, reference)
    per_seed = paired.groupby("seed").apply(lambda d: float(d.a.mean() - d.b.mean()), include_groups=False)
    over_seeds = t_interval(per_seed.to_numpy())
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
    contrast = paired_contrast(a, b, ObjectBootstrap(objects, n_boot, seed))
    rounded = lambda x: None if x is None else round(float(x), 5)  # noqa: E731
    return {
        "mean": rounded(contrast["mean"]),
        "ci_low": rounded(contrast["ci_low"]),
        "ci_high": rounded(contrast["ci_high"]),
        "n_trials": int(len(a)),
        "n_objects": int(len(set(objects))),
        "t_ci_low": rounded(over_seeds["ci_low"]),
        "t_ci_high": rounded(over_seeds["ci_high"]),
        "n_seeds": over_seeds["n_seeds"],
        "per_seed": {str(k): round(v, 5) for k, v in per_seed.items()},
        **counts,
    }


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
    :class:`~graspaug.experiments.sim.PreparedObject` of the trials; ``chosen``: arm → (pool, ratio, base size)."""
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
    for obj in objects:
        sel = trials.object == obj.name
        rates = {arm: rate_summary(trials.success[sel & (trials.arm == arm)]) for arm in chosen}
        metrics["per_object"][obj.name] = {
            "kind": obj.kind,
            "mass": round(obj.body.mass, 4),
            "friction": round(obj.body.lateral_friction, 4),
            **rates,
        }
    return metrics


def sim_headline(summary: dict) -> dict[str, dict]:
    """The experiment's metrics from its :func:`summarize` report: per contrast the mean paired success
    difference and its 95% bootstrap interval over objects (:func:`~graspaug.experiments.stats.headline`),
    and, as ``ranking_<contrast>``, the paired difference in ROC AUC against the cell's outcomes of the
    executed calibration grasps (``summary["ranking"]``, :func:`graspaug.experiments.cell_ranking.cell_ranking`)."""
    ranking = (summary.get("ranking") or {}).get("contrasts", {})
    return {
        **{name: headline(c) for name, c in summary["contrasts"].items()},
        **{f"ranking_{name}": headline(c) for name, c in ranking.items()},
    }


def objects_table(objects: Sequence) -> pd.DataFrame:
    """One row per object (:class:`~graspaug.experiments.sim.PreparedObject`): name, kind, extents (m),
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


def success_bar_data(metrics: dict, chosen: dict) -> tuple[list[str], dict[str, tuple[np.ndarray, ...]]]:
    """What :func:`graspaug.plots.success_bars` draws: the objects and ``all``, and per arm's label
    (rate, Wilson low, Wilson high), each (objects + 1,)."""
    names = [*metrics["per_object"], "all"]
    bars = {}
    for arm, (pool, ratio, base_size) in chosen.items():
        label = (
            "random antipodal grasp (no network)"
            if pool is None
            else f"{arm} ({pool}, B = {base_size}, ratio {ratio:g})"
        )
        stats = [metrics["per_object"][n][arm] for n in names[:-1]] + [metrics["arms"][arm]]
        bars[label] = tuple(np.array([s[key] for s in stats]) for key in ("success_rate", "wilson_low", "wilson_high"))
    return names, bars


def _number(x) -> str:
    return "n/a" if x is None else f"{x:.3f}"


def _t(c: dict) -> str:
    """A contrast's t-interval over seeds as a table cell ("–" with one seed)."""
    return "–" if c["t_ci_low"] is None else f"[{c['t_ci_low']:+.3f}, {c['t_ci_high']:+.3f}]"


def _interval(c: dict) -> str:
    return f"{c['mean']:+.3f} [{c['ci_low']:+.3f}, {c['ci_high']:+.3f}]"


def _verdict(name: str, c: dict) -> str:
    """One sentence on a pick contrast's bootstrap interval, scoped to the run's one draw of the data
    (:func:`~graspaug.experiments.stats.draw_verdict`)."""
    arm, reference = CONTRASTS[name]
    evidence = f"({_interval(c)}, {c['n_trials']} paired drops): {draw_verdict(c['ci_low'], c['ci_high'])}."
    if c["ci_low"] > 0:
        return f"`{name}` excludes zero: {arm} succeeds more often than {reference} {evidence}"
    if c["ci_high"] < 0:
        return f"`{name}` excludes zero: {arm} succeeds less often than {reference} {evidence}"
    return f"`{name}` includes zero: no difference shown between {arm} and {reference} {evidence}"


def control_words(contrasts: dict) -> str:
    """Whether the picks can judge training data, in one sentence: its positive control ``real_data``
    (more real training shapes vs ``before``, bootstrap over objects) shows or not, and so whether
    ``after_vs_before`` says anything about augmentation."""
    c = contrasts.get("real_data")
    if c is None:
        return (
            "No positive control (no network of a larger base size): whether these picks can tell better training "
            "data is unknown, so after_vs_before is not read as a test of augmentation."
        )
    if c["ci_low"] > 0:
        return (
            f"The positive control shows: more real training shapes raise pick success ({_interval(c)}), so these "
            "picks can judge training data and after_vs_before is read as a test of augmentation."
        )
    return (
        f"The positive control does not show: more real training shapes do not raise pick success here "
        f"({_interval(c)}), so these picks cannot judge training data and their after_vs_before measures the cell, "
        "not the augmentation."
    )


def ranking_words(ranking: dict) -> str:
    """Whether the networks' ranking of the cell's outcomes can judge training data, in one sentence: its
    positive control ``real_data`` (AUC of more real training shapes vs ``before``) shows or not, and so
    whether its ``after_vs_before`` says anything about augmentation."""
    c, n = ranking["contrasts"].get("real_data"), ranking["n_grasps"]
    if c is None:
        return "No network of a larger base size: the ranking has no positive control, so after_vs_before is not read."
    if c["ci_low"] > 0:
        return (
            f"The positive control shows on the {n} executed grasps: the networks trained on more real shapes rank "
            f"the cell's outcomes better (ROC AUC {_interval(c)}), so this readout can judge training data and its "
            "after_vs_before is read as a test of augmentation."
        )
    return (
        f"The positive control does not show on the {n} executed grasps (ROC AUC {_interval(c)}), so this readout "
        "cannot judge training data either and its after_vs_before is not read as a test of augmentation."
    )


def ranking_lines(ranking: dict) -> list[str]:
    """The report's section on how each arm's networks rank the cell's outcomes of the executed
    calibration grasps (:func:`graspaug.experiments.cell_ranking.cell_ranking`)."""
    ref = ranking["reference"]
    if ref is None:
        return [
            "",
            f"Every one of the {ranking['n_grasps']} executed calibration grasps had the same outcome: the "
            "networks' ranking of the cell's outcomes is not measured.",
        ]
    lines = [
        "",
        "## How the networks rank the cell's outcomes",
        "",
        f"The `grasp_calibration` stage executed {ranking['n_grasps']} labelled test grasps on "
        f"{ranking['n_objects']} shapes in this cell. Every network scored those datapoints; its ROC AUC against "
        "what the cell did with them says how well it ranks the grasps that held through the lift and the shake. "
        "All arms are scored on the same executed grasps: no drop, sensor noise or planner search differs between "
        f"them. For reference, the robust ε ranks them at {ref['eps']:.3f}, the label at {ref['label']:.3f}. "
        "The networks' ROC AUC against the grasps' labels is beside it (means over training seeds). Intervals: "
        "95% bootstrap over the shapes, 95% t over training seeds.",
        "",
        "| arm | ROC AUC against the cell's outcomes | against the labels |",
        "|---|---|---|",
        *[f"| {arm} | {a['auc']:.3f} | {_number(a.get('auc_label'))} |" for arm, a in ranking["arms"].items()],
        "",
        "| contrast | AUC difference | 95% bootstrap (shapes) | 95% t (seeds) |",
        "|---|---|---|---|",
    ]
    for name, c in ranking["contrasts"].items():
        lines.append(f"| {name} | {c['mean']:+.3f} | [{c['ci_low']:+.3f}, {c['ci_high']:+.3f}] | {_t(c)} |")
    lines += ["", f"**{ranking_words(ranking)}**", ""]
    c = ranking["contrasts"].get("after_vs_before")
    if c is not None and ranking["contrasts"].get("real_data", {}).get("ci_low", 0) > 0:
        shown = "raises" if c["ci_low"] > 0 else "lowers" if c["ci_high"] < 0 else "shows no change in"
        lines.append(f"- Augmentation {shown} the networks' ranking of the cell's outcomes ({_interval(c)}).")
    return lines


def report_text(metrics: dict, trials: pd.DataFrame, calibration_table: pd.DataFrame, scores_file: str) -> str:
    """The report (markdown): rates, contrasts with their verdicts, per seed and per object,
    outcomes, and the calibration table. ``scores_file``: where the graspness labels come from
    (named in the calibration's text)."""
    setup, arms = metrics["setup"], metrics["arms"]
    noise = "D435-like noise, missing pixels and 1 mm steps" if setup["sensor_noise"] else "exact depth"
    shake = (
        f"shaken at {setup['shake_acceleration']:g} g after the lift" if setup["shake_acceleration"] else "not shaken"
    )
    drops = f"{setup['attempts']} seeded drop{'' if setup['attempts'] == 1 else 's'}"
    lines = [
        "# Simulated robot trials",
        "",
        f"Franka Panda in pybullet, overhead depth camera {setup['camera_height']} m above the table ({noise}), "
        f"{setup['objects']} objects × {drops}, the same drops and planner seeds for every arm; networks of "
        f"training seeds {setup['model_seeds']} (B = {setup['base_size']}). "
        f"Grip {setup['grip_force']:g} N, the object {shake}. Success = the object ends inside the bin.",
        "",
        draw_scope(setup["data_seed"], setup["model_seeds"], "sim"),
        "",
        "| arm | planner | successes | rate | 95% Wilson interval |",
        "|---|---|---|---|---|",
    ]
    for arm, a in arms.items():
        planner = (
            "a random antipodal seed grasp, no network"
            if arm == "antipodal"
            else f"{a['pool']} B = {a.get('base_size', setup['base_size'])}, ratio {a['ratio']:g}"
        )
        lines.append(
            f"| {arm} | {planner} | {a['successes']}/{a['attempts']} | {a['success_rate']:.2f} | "
            f"[{a['wilson_low']:.2f}, {a['wilson_high']:.2f}] |"
        )
    lines += [
        "",
        "## Contrasts",
        "",
        "Paired success difference (arm − reference) over the attempts of every "
        "training seed; 95% percentile bootstrap interval with the objects as the unit (each resampled object "
        "brings all its attempts), and the 95% t-interval over training seeds of the per-seed differences. "
        "Against the antipodal arm (one run per drop) a drop counts once, the network's outcomes averaged over "
        "the seeds. No McNemar test: the picks cluster by object and seed.",
        "",
        "| contrast | difference | 95% bootstrap (objects) | 95% t (seeds) | paired drops | objects |",
        "|---|---|---|---|---|---|",
    ]
    for name, c in metrics["contrasts"].items():
        lines.append(
            f"| {name} | {c['mean']:+.3f} | [{c['ci_low']:+.3f}, {c['ci_high']:+.3f}] | {_t(c)} | "
            f"{c['n_trials']} | {c['n_objects']} |"
        )
    lines += ["", f"**{control_words(metrics['contrasts'])}**", ""]
    lines += [f"- {_verdict(name, c)}" for name, c in metrics["contrasts"].items()]
    if metrics["same_network"]:
        lines.append(
            f'- The best ratio on validation AP for B = {setup["base_size"]} is 0: "after" is the same '
            'network as "before".'
        )
    seeds = metrics["per_seed"]
    if len(seeds) > 1:
        lines += [
            "",
            "| training seed | before | after | difference | only before / only after |",
            "|---|---|---|---|---|",
        ]
        for seed, row in seeds.items():
            before, after, paired = row["before"], row["after"], row["paired"]
            lines.append(
                f"| {seed} | {before['successes']}/{before['attempts']} | {after['successes']}/"
                f"{after['attempts']} | {row['difference']:+.2f} | {paired['only_before']} / {paired['only_after']} |"
            )
        if len({np.sign(row["difference"]) for row in seeds.values()} - {0.0}) > 1:
            lines.append("\nThe sign of after − before changes with the training seed.")
    if metrics.get("ranking"):
        lines += ranking_lines(metrics["ranking"])
    names = list(arms)
    lines += [
        "",
        "| object | kind | mass (kg) | friction | " + " | ".join(names) + " |",
        "|---|---|---|---|" + "---|" * len(names),
    ]
    for name, row in metrics["per_object"].items():
        lines.append(
            f"| {name} | {row['kind']} | {row['mass']:.3f} | {row['friction']:.2f} | "
            + " | ".join(f"{row[arm]['successes']}/{row[arm]['attempts']}" for arm in names)
            + " |"
        )
    counts = trials.groupby(["arm", "outcome"]).size().unstack(fill_value=0)
    lines += [
        "",
        "Outcomes (no_grasp: no antipodal pair on the image; collision: the hand pressed on the object, the "
        "table or the bin before closing; not_lifted: the object stayed on the table; dropped: lost on the way; "
        "outside_bin: released but not in the bin):",
        "",
        "| arm | " + " | ".join(counts.columns) + " |",
        "|---|" + "---|" * len(counts.columns),
    ]
    for arm, row in counts.iterrows():
        lines.append(f"| {arm} | " + " | ".join(str(int(v)) for v in row) + " |")
    cal = metrics["calibration"]
    rho = (
        "not computed (fewer than 3 labelled objects or no spread)"
        if cal["spearman"] is None
        else f"{cal['spearman']:+.2f} (p = {cal['p_value']:.3g})"
    )
    lines += [
        "",
        "## Calibration",
        "",
        "Does the cell reward what the labels call a good grasp? The random "
        "antipodal arm's success per object against the object's graspness (share of its sampled grasps with "
        f"robust ε above the grasp threshold, `{scores_file}`; n/a for objects without labels). Spearman "
        f"correlation over {cal['n_objects']} labelled objects: {rho}.",
        "",
        "| object | kind | attempts | sim success (antipodal) | graspness |",
        "|---|---|---|---|---|",
    ]
    for row in calibration_table.itertuples():
        label = "n/a" if np.isnan(row.graspness) else f"{row.graspness:.2f}"
        lines.append(f"| {row.object} | {row.kind} | {row.attempts} | {row.sim_success:.2f} | {label} |")
    return "\n".join(lines) + "\n"


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


def outcome_words(metrics: dict, timing: dict) -> str:
    """One line on the trials: successes/attempts per arm, each contrast's mean [95 % bootstrap
    interval] (:func:`summarize` metrics; the ranking's as ``ranking_<contrast>``) and the planning
    time per grasp, mean and max (s;
    :func:`planning_timing`)."""
    rates = ", ".join(f"{arm} {a['successes']}/{a['attempts']}" for arm, a in metrics["arms"].items())
    ranked = {f"ranking_{n}": c for n, c in (metrics.get("ranking") or {}).get("contrasts", {}).items()}
    contrasts = ", ".join(
        f"{n} {c['mean']:+.3f} [{c['ci_low']:+.3f}, {c['ci_high']:+.3f}]"
        for n, c in {**metrics["contrasts"], **ranked}.items()
    )
    return "%s; %s; planning %.3f s per grasp (max %.3f)" % (
        rates,
        contrasts,
        timing["planning_time_mean"] or 0,
        timing["planning_time_max"] or 0,
    )
