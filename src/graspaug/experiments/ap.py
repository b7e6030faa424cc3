"""The GQ-CNN augmentation experiment's numbers: test AP per network, the AP table over seeds,
paired gains and their verdicts in words, per-object AP, and the report's text (paper Section IV-C/D).

A network is (pool, base size B, ratio R, seed); its summary and test predictions live in
``models/gqcnn/<pool>/<B>-<R>-s<seed>/``.
"""
from __future__ import annotations

import json

import numpy as np
import pandas as pd
from sklearn.metrics import average_precision_score

from graspaug.paths import gqcnn_model_dir


def variants(gen, cfg) -> list[tuple[str, int, float, int]]:
    """(pool, base size, ratio, seed) of every network the ``generate`` and ``gqcnn`` params sections ask for."""
    out = [("targeted", b, float(r), s) for b in gen.base_sizes for r in gen.ratios for s in cfg.seeds]
    out += [("random", b, float(r), s) for b in cfg.random_base_sizes for r in cfg.random_ratios for s in cfg.seeds]
    return out


def collect(variants: list[tuple[str, int, float, int]]) -> pd.DataFrame:
    """One row per network: pool, base_size, ratio, seed, ap, accuracy, roc_auc."""
    rows = []
    for pool, base, ratio, seed in variants:
        path = gqcnn_model_dir(pool, base, ratio, seed) / "summary.json"
        if not path.exists():
            raise FileNotFoundError(f"{path} is missing: run `dvc repro train_gqcnn train_gqcnn_random` first")
        test = json.loads(path.read_text())["test"]
        rows.append({"pool": pool, "base_size": base, "ratio": ratio, "seed": seed, "ap": test["ap"], "accuracy": test["accuracy"], "roc_auc": test["roc_auc"]})
    return pd.DataFrame(rows)


def ap_table(runs: pd.DataFrame) -> pd.DataFrame:
    """Mean, standard deviation (over seeds; NaN for one seed) and count of test AP per pool,
    base size and ratio. The random curve shares ratio 0 (no generated shapes) with targeted."""
    zero = runs[(runs.pool == "targeted") & (runs.ratio == 0.0) & runs.base_size.isin(runs.base_size[runs.pool == "random"])]
    runs = pd.concat([runs, zero.assign(pool="random")], ignore_index=True)
    table = runs.groupby(["pool", "base_size", "ratio"]).ap.agg(ap_mean="mean", ap_std="std", n="count").reset_index()
    return table.sort_values(["pool", "base_size", "ratio"], ascending=[False, True, True], ignore_index=True)


def paired_gain(runs: pd.DataFrame, a: tuple[str, float], b: tuple[str, float], base: int) -> dict:
    """Mean and standard error over seeds of AP(a) - AP(b), each seed's two networks paired
    (``a``, ``b``: (pool, ratio); ratio 0 of any pool is the targeted network)."""
    def series(pool: str, ratio: float) -> pd.Series:
        pool = "targeted" if ratio == 0.0 else pool
        rows = runs[(runs.pool == pool) & (runs.base_size == base) & (runs.ratio == ratio)]
        return rows.set_index("seed").ap

    diff = (series(*a) - series(*b)).dropna()
    n = len(diff)
    se = float(diff.std(ddof=1) / np.sqrt(n)) if n > 1 else float("nan")
    mean = float(diff.mean()) if n else float("nan")
    return {"mean": mean, "se": se if np.isfinite(se) else None, "n": n, "beyond_2se": bool(n > 1 and np.isfinite(se) and mean > 2 * se)}


def verdicts(runs: pd.DataFrame, table: pd.DataFrame) -> tuple[dict, list[str]]:
    """Best ratio per base size (chosen on the test AP itself) and whether augmentation, and
    targeting, beat the seed-to-seed variation: the per-seed paired gain must exceed twice its
    standard error (about a t-test at 5%; it needs at least two seeds)."""
    summary, words = {}, []
    targeted = table[table.pool == "targeted"]
    for base, rows in targeted.groupby("base_size"):
        rows = rows.dropna(subset=["ap_mean"])
        if not (rows.ratio == 0.0).any():
            words.append(f"B = {base}: no test AP at ratio 0 (the test set needs both labels).")
            continue
        best = rows.loc[rows.ap_mean.idxmax()]
        zero = rows[rows.ratio == 0.0].iloc[0]
        gain = paired_gain(runs, ("targeted", float(best.ratio)), ("targeted", 0.0), base)
        summary[str(base)] = {"best_ratio": float(best.ratio), "best_ap": round(float(best.ap_mean), 5), "ap_ratio_0": round(float(zero.ap_mean), 5),
                              "gain": round(gain["mean"], 5), "gain_se": None if gain["se"] is None else round(gain["se"], 5), "seeds": gain["n"],
                              "beyond_seed_spread": gain["beyond_2se"]}
        if best.ratio == 0.0:
            words.append(f"B = {base}: no augmentation ratio beat training on the {base} base shapes alone (AP {zero.ap_mean:.4f} at 1:0).")
        elif gain["se"] is None:
            words.append(f"B = {base}: the highest test AP is at 1:{best.ratio:g} ({best.ap_mean:.4f} vs {zero.ap_mean:.4f} at 1:0, {gain['mean']:+.4f}); "
                         "with one seed there is no seed spread to judge that by, so it is not evidence of an improvement.")
        else:
            words.append(f"B = {base}: the highest test AP is at 1:{best.ratio:g} ({best.ap_mean:.4f} vs {zero.ap_mean:.4f} at 1:0); the per-seed gain "
                         f"is {gain['mean']:+.4f} ± {gain['se']:.4f} (standard error, {gain['n']} seeds), "
                         + ("more than twice its standard error: an improvement beyond the seed spread."
                            if gain["beyond_2se"] else "not more than twice its standard error: within the seed spread, not an improvement we can claim.")
                         + " (The best ratio was picked on the same test AP, which favours finding a gain.)")
    for base in sorted(set(runs.base_size[runs.pool == "random"])):
        ratios = sorted(set(runs.ratio[(runs.pool == "random") & (runs.base_size == base)]))
        gains = {r: paired_gain(runs, ("targeted", r), ("random", r), base) for r in ratios}
        higher = sum(g["mean"] > 0 for g in gains.values())
        beyond = sum(g["beyond_2se"] for g in gains.values())
        summary[f"targeted_vs_random_{base}"] = {f"{r:g}": {k: (round(v, 5) if isinstance(v, float) else v) for k, v in g.items()} for r, g in gains.items()}
        seeds = max((g["n"] for g in gains.values()), default=0)
        if seeds == 0:
            words.append(f"Targeted vs random augmentation at B = {base}: no test AP to compare (the test set needs both labels).")
            continue
        words.append(f"Targeted vs random augmentation at B = {base}: targeted has the higher test AP at {higher} of {len(ratios)} ratios "
                     "(AP differences " + ", ".join(f"1:{r:g} {g['mean']:+.4f}" for r, g in gains.items()) + "); "
                     + (f"{beyond} of them by more than twice the standard error over {seeds} seeds." if seeds > 1
                        else "one seed, so no spread to judge them by."))
    return summary, words


def per_object_ap(labels: np.ndarray, probability: np.ndarray, shape_ids: np.ndarray) -> pd.Series:
    """AP per test object (those with both classes among their datapoints)."""
    frame = pd.DataFrame({"label": labels.astype(int), "p": probability, "shape_id": shape_ids})
    values = {s: average_precision_score(g.label, g.p) for s, g in frame.groupby("shape_id") if 0 < g.label.sum() < len(g)}
    return pd.Series(values, dtype=float)


def predictions(pool: str, base: int, ratio: float, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """One network's test predictions and their rows in the original index."""
    folder = gqcnn_model_dir(pool, base, ratio, seed)
    return np.load(folder / "test_predictions.npy"), np.load(folder / "test_rows.npy")


def improvement_panels(base_set: pd.DataFrame, generated: pd.DataFrame, generated_graspness: np.ndarray, test_rarity: np.ndarray,
                       test_graspness: np.ndarray, improvement: np.ndarray) -> list[dict]:
    """Fig. 8's two panels (rarity against the base set, graspness): bin edges, the selected and
    generated shapes' scores, and the mean per-object AP change of the test objects per bin."""
    panels = []
    for name, selected, made, test_values in (
            ("rarity (against the base set)", base_set.rarity[base_set.selected_by_rarity], generated.rarity_vs_base, test_rarity),
            ("graspness", base_set.graspness[base_set.selected_by_graspness], pd.Series(generated_graspness), test_graspness)):
        values = np.concatenate([selected, made, test_values])
        edges = np.linspace(0.0 if name == "graspness" else float(np.min(values)), float(np.quantile(values, 0.99)) + 1e-9, 9)
        test_values = np.clip(test_values, edges[0], edges[-1])
        bins = np.clip(np.digitize(test_values, edges) - 1, 0, len(edges) - 2)
        means = [float(improvement[bins == b].mean()) if (bins == b).any() else np.nan for b in range(len(edges) - 1)]
        panels.append({"name": name, "edges": edges, "selected": np.asarray(selected), "generated": np.asarray(made), "improvement": means,
                       "objects": [int((bins == b).sum()) for b in range(len(edges) - 1)]})
    return panels


def report_markdown(table: pd.DataFrame, words: list[str], summary: dict, seeds: list[int], steps: int, batch_size: int) -> str:
    """report.md: the AP table, the verdicts in words, the figures."""
    share = summary.get("test_positive_share")
    lines = ["# GQ-CNN augmentation experiment", "",
             f"Test Average Precision on every test-split grasp of the original corpus; mean ± std over seeds {seeds} "
             f"({steps} SGD steps of {batch_size} per network, whatever the training set's size). "
             f"A predictor without skill has AP = the positive share, {share}; always answering 'fail' has accuracy {None if share is None else round(1 - share, 4)}. "
             "Paper (Fig. 7): best ratios 1:0.5, 1:1.5, 1:2 for B = 50, 100, 200.", ""]
    ratios = sorted(table.ratio.unique())
    lines.append("| pool | B | " + " | ".join(f"1:{r:g}" for r in ratios) + " | best |")
    lines.append("|---|---|" + "---|" * (len(ratios) + 1))
    for (pool, base), rows in table.groupby(["pool", "base_size"], sort=False):
        cells = []
        for r in ratios:
            row = rows[rows.ratio == r]
            if row.empty:
                cells.append("")
            else:
                m, s = row.ap_mean.iloc[0], row.ap_std.iloc[0]
                cells.append("-" if np.isnan(m) else f"{m:.4f}" + ("" if np.isnan(s) else f" ± {s:.4f}"))
        best = f"1:{rows.loc[rows.ap_mean.idxmax(), 'ratio']:g}" if rows.ap_mean.notna().any() else "-"
        lines.append(f"| {pool} | {base} | " + " | ".join(cells) + f" | {best} |")
    lines += ["", "## What the numbers say", ""] + [f"- {w}" for w in words]
    per = summary["per_object"]
    lines += [f"- Per object (B = {per['base_size']}, 1:{per['ratio']:g} vs 1:0): mean AP change {per['mean_improvement']}, "
              f"improved on {per['improved_share']} of {per['objects']} test objects with both labels.", "",
              "![AP vs ratio](ap_vs_ratio.png)", "", "![Per-object improvement](improvement_by_score.png)", "", "![t-SNE](tsne_graspness.png)", ""]
    return "\n".join(lines)
