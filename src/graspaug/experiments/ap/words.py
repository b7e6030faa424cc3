"""The AP experiment in words: each contrast's verdict, the share of the real-shape gain, report.md."""

from __future__ import annotations

import numpy as np
import pandas as pd

from graspaug.experiments.stats import (
    draw_scope,
    fieller_interval,
)
from graspaug.experiments.stats import (
    verdict as contrast_verdict,
)


def gain_sentences(
    results: dict, table: pd.DataFrame, chosen: dict[int, float], augment_base_sizes, ceiling_shapes: int | None
) -> list[str]:
    """The report's sentences on scale: per augmented base size, targeted augmentation's gain as
    a share of the same number of real shapes' gain (mean over ratios), and, with the ceiling
    (``ceiling_shapes`` train shapes; None without it), the share of the gap from 1:0 to the
    ceiling that the chosen ratio closes. A gap within the ceiling's 95% t half-width is
    reported as no gap rather than as a share of noise. The share of the real-shape gain has a Fieller
    interval over seeds (:func:`~graspaug.experiments.stats.fieller_interval`); the ceiling's share none."""
    out = []
    for b in augment_base_sizes:
        t, r = results.get(f"targeted_vs_none@{b}"), results.get(f"targeted_vs_real@{b}")
        real_gain = (
            t["mean"] - r["mean"] if t and r and None not in (t["mean"], r["mean"]) else 0.0
        )  # mean over R of AP(real, B, R) - AP(B, 1:0)
        if real_gain:
            gain = np.array([np.nan if v is None else v for v in t["per_seed"]], dtype=float)
            real = gain - np.array([np.nan if v is None else v for v in r["per_seed"]], dtype=float)
            ok = np.isfinite(gain) & np.isfinite(real)
            share = fieller_interval(gain[ok], real[ok])
            interval = (
                f"95% Fieller interval over seeds [{share['low']:.0%}, {share['high']:.0%}]"
                if share["bounded"]
                else "the real-shape gain is not clearly nonzero over seeds, so its Fieller interval is unbounded"
            )
            out.append(
                f"At B = {b}, generated shapes give {t['mean'] / real_gain:.0%} of the gain of the same number of "
                f"real shapes ({t['mean']:+.4f} vs {real_gain:+.4f} AP, mean over ratios; {interval})."
            )
    nets = table.set_index(["pool", "base_size", "ratio"])
    if ceiling_shapes is None or ("ceiling", 0, 0.0) not in nets.index:
        return out
    top, half = nets.test_ap[("ceiling", 0, 0.0)], np.nan_to_num(nets.test_ap_ci[("ceiling", 0, 0.0)])
    for b, ratio in chosen.items():
        none, best = nets.test_ap.get(("targeted", b, 0.0)), nets.test_ap.get(("targeted", b, ratio))
        if none is None or best is None or not np.isfinite(top - none) or not np.isfinite(best):
            continue
        head = f"B = {b}: the ceiling (all {ceiling_shapes} train shapes outside validation) reaches {top:.4f}"
        if abs(top - none) <= half:
            out.append(
                f"{head}, within its 95% interval (±{half:.4f}) of 1:0 ({none:.4f}): no gap for augmentation to close "
                "at this budget."
            )
        elif top < none:
            out.append(
                f"{head}, below 1:0 ({none:.4f}): at this budget more shapes do not raise AP beyond B = {b}; no gap "
                "to close."
            )
        else:
            out.append(
                f"{head}; 1:{ratio:g} closes {(best - none) / (top - none):.0%} of the gap from 1:0 ({none:.4f})."
            )
    return out


def verdict(name: str, c: dict) -> str:
    """One sentence: does the contrast's interval exclude zero, by both intervals; the words scoped to
    the run's one draw of the data (:func:`~graspaug.experiments.stats.draw_verdict`)."""
    if c["mean"] is None:
        return f"`{name}` ({c['meaning']}): no value (a test set with one class?)."
    if c["seeds_low"] is None:
        return f"`{name}` ({c['meaning']}): {c['mean']:+.4f} with one seed, no interval; not evidence either way."
    t_side = "above zero" if c["seeds_low"] > 0 else ("below zero" if c["seeds_high"] < 0 else "includes zero")
    b_side = (
        "above zero"
        if (c["objects_low"] or 0) > 0
        else ("below zero" if (c["objects_high"] or 0) < 0 else "includes zero")
    )
    word = contrast_verdict(c)
    return (
        f"`{name}` ({c['meaning']}): {c['mean']:+.4f} AP, 95% t-interval over {c['n_seeds']} seeds "
        f"[{c['seeds_low']:+.4f}, {c['seeds_high']:+.4f}] "
        f"({t_side}), bootstrap over test objects [{c['objects_low']:+.4f}, {c['objects_high']:+.4f}] ({b_side}): "
        f"{word}."
    )


def _fmt(v, digits: int = 4) -> str:
    return "-" if v is None or (isinstance(v, float) and not np.isfinite(v)) else f"{v:.{digits}f}"


def training_words(t, members: int = 1) -> str:
    """The training budget of ``gqcnn.train`` (a TrainSettings) and ``gqcnn.members`` in words, for the report."""
    what = (
        "Each network"
        if members == 1
        else f"Each network is an ensemble of {members} GQ-CNNs (their mean P(success)); each member"
    )
    return (
        f"{what} trains {t.epochs:g} pass{'' if t.epochs == 1 else 'es'} over its own training set "
        f"({t.min_steps}-{t.max_steps} steps of "
        f"{t.batch_size}), "
        f"the learning rate annealed to {t.final_lr:g} of its start, and keeps the weights with the best validation AP."
    )


def report_markdown(
    table: pd.DataFrame,
    contrasts: dict,
    chosen: dict[int, float],
    extras: list[str],
    seeds,
    positive_share: float,
    train_words: str,
    data_seed: int,
) -> str:
    """report.md: the network table, the contrasts with intervals, the verdicts in words (scoped to the
    draw of the data ``data_seed``: :func:`~graspaug.experiments.stats.draw_scope`), the figures."""
    lines = [
        "# GQ-CNN augmentation experiment",
        "",
        "Every number is test Average Precision on every test-split grasp of the original corpus, over training "
        f"seeds {list(seeds)} of one draw of the data (`data_seed` = {data_seed}); "
        f"± is the 95% t-interval half-width over seeds. {train_words} A predictor without skill has AP = the "
        "positive share, "
        f"{positive_share:.4f}. Ratios are chosen on validation AP (train shapes no network trains on), never on the "
        "test set. "
        "Paper (Fig. 7): best ratios 1:0.5, 1:1.5, 1:2 for B = 50, 100, 200.",
        "",
        "| pool | B | ratio | test AP | per-object AP | validation AP | ROC AUC |",
        "|---|---|---|---|---|---|---|",
    ]
    for r in table.itertuples():
        ratio = "all" if r.pool == "ceiling" else f"1:{r.ratio:g}"
        base = "-" if r.pool == "ceiling" else str(r.base_size)
        ci = "" if not np.isfinite(r.test_ap_ci) else f" ± {r.test_ap_ci:.4f}"
        lines.append(
            f"| {r.pool} | {base} | {ratio} | {_fmt(r.test_ap)}{ci} | {_fmt(r.per_object_ap)} | {_fmt(r.val_ap)} | "
            f"{_fmt(r.test_roc_auc)} |"
        )
    lines += [
        "",
        "## Contrasts (declared before any network was read)",
        "",
        "| contrast | mean | 95% t-interval | SD over seeds | 95% bootstrap (objects) |",
        "|---|---|---|---|---|",
    ]
    for name, c in contrasts.items():
        lines.append(
            f"| `{name}` | {_fmt(c['mean'])} | [{_fmt(c['seeds_low'])}, {_fmt(c['seeds_high'])}] | {_fmt(c['sd'])} | "
            f"[{_fmt(c['objects_low'])}, {_fmt(c['objects_high'])}] |"
        )
    excluding = [n for n, c in contrasts.items() if contrast_verdict(c).startswith(("a gain", "a loss"))]
    lines += [
        "",
        "## What the numbers say",
        "",
        draw_scope(data_seed, seeds, "ap"),
        "",
        "- Contrasts whose t-interval excludes zero: "
        f"{', '.join(f'`{n}`' for n in excluding) if excluding else 'none'}.",
    ]
    lines += [f"- {verdict(n, c)}" for n, c in contrasts.items()]
    if chosen:
        lines.append(
            "- Ratios chosen on validation AP: " + ", ".join(f"B = {b}: 1:{r:g}" for b, r in chosen.items()) + "."
        )
    lines += [f"- {e}" for e in extras]
    lines += [
        "",
        "![AP vs ratio](ap_vs_ratio.png)",
        "",
        "![Per-object improvement](improvement_by_score.png)",
        "",
        "![t-SNE](tsne_graspness.png)",
        "",
    ]
    return "\n".join(lines)
