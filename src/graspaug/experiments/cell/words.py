"""The cell in words: each contrast's verdict, the positive control's and the ranking's sentences, report.md."""

from __future__ import annotations

import numpy as np
import pandas as pd

from graspaug.experiments.cell.numbers import CONTRASTS
from graspaug.experiments.cell.picks import ANTIPODAL, ORACLE, ORACLE_FIT, oracle_fit
from graspaug.experiments.stats import (
    draw_scope,
    verdict,
)


def _number(x) -> str:
    return "n/a" if x is None else f"{x:.3f}"


def _t(c: dict) -> str:
    """A contrast's t-interval over seeds as a secondary table cell ("–" with one seed; "too few seeds" where it would
    leave the difference's range [−1, 1]: :func:`~graspaug.experiments.stats.t_interval`)."""
    if c["seeds_low"] is None:
        return "–" if (c.get("n_seeds") or 0) < 2 else "too few seeds"
    return f"[{c['seeds_low']:+.3f}, {c['seeds_high']:+.3f}]"


def _interval(c: dict) -> str:
    return f"{c['mean']:+.3f} [{c['objects_low']:+.3f}, {c['objects_high']:+.3f}]"


def _verdict(name: str, c: dict) -> str:
    """One sentence on a pick contrast's bootstrap interval, scoped to the run's one draw of the data
    (:func:`~graspaug.experiments.stats.draw_verdict`)."""
    arm, reference = CONTRASTS[name]
    evidence = f"({_interval(c)}, {c['n_trials']} paired drops): {verdict(c)}."
    if c["objects_low"] > 0:
        return f"`{name}` excludes zero: {arm} succeeds more often than {reference} {evidence}"
    if c["objects_high"] < 0:
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
    if c["objects_low"] > 0:
        return (
            f"The positive control shows: more real training shapes raise pick success ({_interval(c)}), so these "
            "picks can judge training data and after_vs_before is read as a test of augmentation."
        )
    return (
        f"The positive control does not show: more real training shapes do not raise pick success here "
        f"({_interval(c)}), so these picks cannot judge training data and their after_vs_before measures the cell, "
        "not the augmentation."
    )


def oracle_words(rate: float | None, missing: str = "no oracle arm") -> str:
    """Whether the cell is fit to compare planners, as a clause: the oracle's pick rate on the feasible attempts
    ``rate`` against :data:`~graspaug.experiments.cell.picks.ORACLE_FIT`; ``missing`` says why there is none (None)."""
    if rate is None:
        return f"{missing}: whether the cell can tell planners apart is unknown"
    head = f"the oracle picks {rate:.0%} of feasible attempts: "
    if oracle_fit(rate):
        return head + "the cell is fit to compare planners"
    return head + f"below {ORACLE_FIT:.0%}, the cell is NOT fit to compare planners here (its physics caps success)"


def feasible_count(n: int, total: int, unit: str) -> str:
    """The opening words of a report's feasible-objects section, the same in the sim stage's report and the picks'."""
    return f"Feasible objects first: {n} of {total} {unit}"


def feasible_lines(feasibility: dict) -> list[str]:
    """The report's first lines (:func:`~graspaug.experiments.cell.numbers.feasible_first`): whether the oracle makes
    the cell fit to compare planners, then each arm's success on the feasible objects and on all objects beside it,
    with their counts and each arm's share of the oracle − antipodal span."""
    feasible, every = feasibility["feasible"], feasibility["all"]
    verdict = oracle_words(feasibility["oracle_rate"], "no object is feasible")
    lines = [f"**{verdict[0].upper()}{verdict[1:]}.**", ""]
    lines.append(
        f"{feasible_count(feasible['objects'], every['objects'], 'objects')} are feasible by geometry alone "
        "(a top-down parallel jaw fits across them in at least half of their landing probability, "
        "`graspaug.sim.feasibility`; judged before any pick). Success on them, all objects beside; the share of the "
        "oracle − antipodal span where the oracle picks more often than the antipodal floor:"
    )

    def cells(part: dict, arm: str) -> str:
        a = part["arms"].get(arm)
        if a is None:
            return "– | – | –"
        share = part["span_share"].get(arm)
        shown = "" if share is None else f"{share:.2f}"
        return f"{a['successes']}/{a['attempts']} | {a['success_rate']:.2f} | {shown}"

    lines += [
        "",
        f"| arm | feasible objects ({feasible['objects']}): successes | rate | share of span "
        f"| all objects ({every['objects']}): successes | rate | share of span |",
        "|---|---|---|---|---|---|---|",
        *(f"| {arm} | {cells(feasible, arm)} | {cells(every, arm)} |" for arm in every["arms"]),
        "",
    ]
    return lines


def ranking_words(ranking: dict) -> str:
    """Whether the networks' ranking of the cell's outcomes can judge training data, in one sentence: its
    positive control ``real_data`` (AUC of more real training shapes vs ``before``) shows or not, and so
    whether its ``after_vs_before`` says anything about augmentation."""
    c, n = ranking["contrasts"].get("real_data"), ranking["n_grasps"]
    if c is None:
        return "No network of a larger base size: the ranking has no positive control, so after_vs_before is not read."
    if c["objects_low"] > 0:
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
    calibration grasps (:func:`graspaug.experiments.cell.numbers.cell_ranking`)."""
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
        "95% bootstrap over the shapes, which the verdicts read; the 95% t over training seeds is a secondary column, "
        "never judged on its own.",
        "",
        "| arm | ROC AUC against the cell's outcomes | against the labels |",
        "|---|---|---|",
        *[f"| {arm} | {a['auc']:.3f} | {_number(a.get('auc_label'))} |" for arm, a in ranking["arms"].items()],
        "",
        "| contrast | AUC difference | 95% bootstrap (shapes) | secondary: 95% t (seeds) |",
        "|---|---|---|---|",
    ]
    for name, c in ranking["contrasts"].items():
        lines.append(f"| {name} | {c['mean']:+.3f} | [{c['objects_low']:+.3f}, {c['objects_high']:+.3f}] | {_t(c)} |")
    lines += ["", f"**{ranking_words(ranking)}**", ""]
    c = ranking["contrasts"].get("after_vs_before")
    if c is not None and ranking["contrasts"].get("real_data", {}).get("objects_low", 0) > 0:
        shown = "raises" if c["objects_low"] > 0 else "lowers" if c["objects_high"] < 0 else "shows no change in"
        lines.append(f"- Augmentation {shown} the networks' ranking of the cell's outcomes ({_interval(c)}).")
    return lines


#: What the arms without a network plan with, as the report names it.
PLANNERS = {
    ANTIPODAL: "a random antipodal seed grasp, no network (the floor)",
    ORACLE: "the best collision-free grasp on the true mesh in its resting pose, no camera (the ceiling)",
}


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
        *(feasible_lines(metrics["feasibility"]) if "feasibility" in metrics else []),
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
        planner = PLANNERS.get(arm) or f"{a['pool']} B = {a.get('base_size', setup['base_size'])}, ratio {a['ratio']:g}"
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
        "brings all its attempts), the interval every verdict reads; secondary, never judged on its own: the 95% "
        't-interval over training seeds of the per-seed differences ("too few seeds" where it would leave [−1, 1]). '
        "Against the antipodal arm (one run per drop) a drop counts once, the network's outcomes averaged over "
        "the seeds. No McNemar test: the picks cluster by object and seed.",
        "",
        "| contrast | difference | 95% bootstrap (objects) | secondary: 95% t (seeds) | paired drops | objects |",
        "|---|---|---|---|---|---|",
    ]
    for name, c in metrics["contrasts"].items():
        lines.append(
            f"| {name} | {c['mean']:+.3f} | [{c['objects_low']:+.3f}, {c['objects_high']:+.3f}] | {_t(c)} | "
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
        "outside_bin: released but not in the bin; for the oracle, no_grasp: no collision-free grasp with a level "
        "jaw on the mesh):",
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


def outcome_words(metrics: dict, timing: dict) -> str:
    """One line on the trials: successes/attempts per arm, each contrast's mean [95 % bootstrap
    interval] (:func:`summarize` metrics; the ranking's as ``ranking_<contrast>``) and the planning
    time per grasp, mean and max (s;
    :func:`planning_timing`)."""
    rates = ", ".join(f"{arm} {a['successes']}/{a['attempts']}" for arm, a in metrics["arms"].items())
    ranked = {f"ranking_{n}": c for n, c in (metrics.get("ranking") or {}).get("contrasts", {}).items()}
    contrasts = ", ".join(
        f"{n} {c['mean']:+.3f} [{c['objects_low']:+.3f}, {c['objects_high']:+.3f}]"
        for n, c in {**metrics["contrasts"], **ranked}.items()
    )
    return "%s; %s; planning %.3f s per grasp (max %.3f)" % (
        rates,
        contrasts,
        timing["planning_time_mean"] or 0,
        timing["planning_time_max"] or 0,
    )


def picks_feasible_lines(feasible: dict, text) -> list[str]:
    """The picks report's first lines (:func:`~graspaug.experiments.cell.picks.feasible_summary`): success on the
    feasible objects (declared from geometry), the oracle's verdict on the cell and each arm's share of the oracle −
    antipodal span; ``text`` words a rate with its interval."""
    if not feasible:
        return ["No feasible object (or no `feasible` column): every figure below is on all objects.", ""]
    verdict = oracle_words(feasible.get("oracle_rate"))
    span = feasible.get("span_share", {})
    return [
        f"{feasible_count(feasible['object_draws'], feasible['all_object_draws'], 'object-draws')} "
        f"({feasible['attempts']} attempts); {verdict}.",
        "",
        "| arm (feasible objects) | success rate [95%] | share of oracle − antipodal |",
        "|---|---|---|",
        *(
            f"| {a} | {text(c, '')} | {span[a]:.2f} |" if a in span else f"| {a} | {text(c, '')} | |"
            for a, c in feasible["summary"]["arms"].items()
        ),
        "",
        "All objects:",
        "",
    ]
