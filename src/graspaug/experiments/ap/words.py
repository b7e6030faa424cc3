"""The AP experiment in words: each contrast's verdict, the share of the real-shape gain, report.md."""

from __future__ import annotations

import numpy as np
import pandas as pd

from graspaug.experiments.ap.attribution import share_sentence
from graspaug.experiments.stats import draw_scope, interval, interval_text
from graspaug.experiments.stats import verdict as contrast_verdict


def gain_sentences(
    shares: dict, table: pd.DataFrame, chosen: dict[int, float], ceiling_shapes: int | None
) -> list[str]:
    """The report's sentences on scale: per augmented base size, targeted augmentation's share of the same number of
    real shapes' gain (``shares``: base size → the targeted entry of
    :func:`~graspaug.experiments.ap.attribution.combine_draws`'s ``shares``, the decomposition's own figures: its
    interval by test inversion, unbounded when the real gain's interval holds zero), beside that gain and
    targeted's own; and, with the ceiling (``ceiling_shapes`` train shapes; None without it), the share of the gap
    from 1:0 to the ceiling that the chosen ratio closes. A gap within the ceiling's 95% t half-width is reported
    as no gap rather than as a share of noise; the ceiling's share has no interval."""
    out = [share_sentence("targeted", b, s) for b, s in shares.items()]
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
    """One sentence: the contrast with its one interval (its ``over``: seeds × test objects) and its one verdict,
    scoped to the run's one draw of the data (:func:`~graspaug.experiments.stats.draw_verdict`)."""
    if c["mean"] is None:
        return f"`{name}` ({c['meaning']}): no value (a network without a test AP, or no ratio it can use), no verdict."
    shapes = recon_words(c.get("recon_shapes") or [])
    if None in interval(c):  # no usable interval: say so rather than print one
        seeds = "one seed" if c.get("n_seeds") == 1 else "too few seeds"
        return f"`{name}` ({c['meaning']}): {c['mean']:+.4f} AP, {seeds}, no interval: no verdict.{shapes}"
    return f"`{name}` ({c['meaning']}): {interval_text(c)} AP, {contrast_verdict(c)}.{shapes}"


def recon_words(counts: list[dict]) -> str:
    """`` N of M recon shapes meshed (K dropped)`` per recon network of a contrast (its ``recon_shapes``:
    :func:`~graspaug.experiments.ap.numbers.recon_shapes`), "at 1:R" after each when there are several; empty
    without counts."""
    parts = [
        f"{n['meshed']} of {n['asked']} recon shapes meshed ({n['asked'] - n['meshed']} dropped)"
        + (f" at 1:{n['ratio']:g}" if len(counts) > 1 else "")
        for n in counts
    ]
    return f" {'; '.join(parts)}." if parts else ""


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
        ci = f" ± {r.test_ap_ci:.4f}" if np.isfinite(r.test_ap_ci) else ""
        ci = " (too few seeds for ±)" if not ci and getattr(r, "n_seeds", 1) > 1 else ci  # ± would leave [0, 1]
        lines.append(
            f"| {r.pool} | {base} | {ratio} | {_fmt(r.test_ap)}{ci} | {_fmt(r.per_object_ap)} | {_fmt(r.val_ap)} | "
            f"{_fmt(r.test_roc_auc)} |"
        )
    lines += [
        "",
        "## Contrasts (declared before any network was read)",
        "",
        "Each contrast is judged by one interval over training seeds and test objects together (the one every report "
        "quotes: the seeds' t half-width and the object bootstrap's normal one in quadrature; none with one seed). "
        "Secondary columns, never judged on their own: the 95% t-interval over seeds "
        '("too few seeds" where it would leave [−1, 1]), the SD over seeds, the bootstrap over test objects alone.',
        "",
        "| contrast | mean [95% interval: seeds × objects] | verdict | t over seeds | SD over seeds | objects alone |",
        "|---|---|---|---|---|---|",
    ]
    for name, c in contrasts.items():
        t_cell = "too few seeds" if c["seeds_low"] is None else f"[{_fmt(c['seeds_low'])}, {_fmt(c['seeds_high'])}]"
        word = "-" if c["mean"] is None else contrast_verdict(c)  # no interval: "no interval … no verdict"
        lines.append(
            f"| `{name}` | {interval_text(c)} | {word} | {t_cell} | {_fmt(c['sd'])} | "
            f"[{_fmt(c['objects_low'])}, {_fmt(c['objects_high'])}] |"
        )
    excluding = [n for n, c in contrasts.items() if contrast_verdict(c).startswith(("a gain", "a loss"))]
    lines += [
        "",
        "## What the numbers say",
        "",
        draw_scope(data_seed, seeds, "ap"),
        "",
        f"- Contrasts whose interval excludes zero: {', '.join(f'`{n}`' for n in excluding) if excluding else 'none'}.",
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
