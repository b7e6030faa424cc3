"""Stage ``report``: the paper's GQ-CNN experiment in one table, three figures and plain words.

Reads every trained network (``models/gqcnn/<pool>/<B>-<R>-s<seed>/``: summary and test
predictions) that params ask for. Writes ``metrics/ap.json`` (test AP mean / std / n per
pool, base size and ratio; the best ratio per base size; targeted minus random),
``reports/gqcnn/ap_table.csv`` and, in ``reports/gqcnn/``: ``report.md``, ``ap_vs_ratio.png``
(Fig. 7), ``improvement_by_score.png`` (Fig. 8: per-object AP improvement of the largest base
size's best ratio over ratio 0, by rarity and graspness interval, with the histograms of the
selected and generated shapes) and ``tsne_graspness.png`` (Fig. 1: t-SNE of the original
train and generated latents, colored by graspness).
"""
from __future__ import annotations

import json
import logging

import numpy as np
import pandas as pd

from graspaug.config import Params
from graspaug.experiments.ap import ap_table, collect, improvement_panels, per_object_ap, predictions, report_markdown, variants, verdicts
from graspaug.generation import ratio_count
from graspaug.io.atomic import atomic_path
from graspaug.io.tables import read_table, write_csv, write_json
from graspaug.paths import AP_METRICS, LATENTS, REPORT_DIR, SCORES, base_set_table, generated_index, gqcnn_dir, gqcnn_model_dir, grasps_table
from graspaug.scores import rarity

log = logging.getLogger(__name__)


def run(params: Params) -> None:
    from graspaug.plots import ap_vs_ratio, improvement_by_interval, scatter_colored

    asked = variants(params.generate, params.gqcnn)
    runs = collect(asked)  # a missing network is a FileNotFoundError, which the CLI prints in one line
    first = asked[0]
    positive_share = json.loads((gqcnn_model_dir(*first) / "summary.json").read_text())["test"]["positive_share"]
    if runs.ap.isna().all():
        log.warning("report: the test set has only one class, so no network has an AP")
    table = ap_table(runs)
    summary, words = verdicts(runs, table)
    summary["test_positive_share"] = positive_share
    write_csv(table, REPORT_DIR / "ap_table.csv")
    wide = table.assign(curve=table.pool + "_" + table.base_size.astype(str)).pivot(index="ratio", columns="curve", values="ap_mean")
    write_csv(wide.reset_index(), REPORT_DIR / "ap_vs_ratio.csv")  # one column per curve, for `dvc plots`
    asked = {gqcnn_model_dir(*v) for v in asked}
    extra = sorted(str(p) for p in gqcnn_model_dir("targeted", 0, 0, 0).parent.parent.glob("*/*") if p.is_dir() and p not in asked)
    if extra:
        log.warning("report: models/gqcnn holds %d networks params do not ask for (left out; `dvc gc -w` or delete them): %s", len(extra), extra[:4])

    curves = {}
    for (pool, base), rows in table.groupby(["pool", "base_size"], sort=False):
        curves[f"B = {base}, {pool}"] = (rows.ratio.to_numpy(), rows.ap_mean.to_numpy(), np.nan_to_num(rows.ap_std.to_numpy()))
    ap_vs_ratio(curves, REPORT_DIR / "ap_vs_ratio.png", f"Test AP vs augmentation ratio (seeds: {list(params.gqcnn.seeds)}; error bars: std over seeds)")

    # Fig. 8: the largest base size, its best targeted ratio against ratio 0
    base = max(params.generate.base_sizes)
    best = summary.get(str(base), {}).get("best_ratio", 0.0)
    compare = best if best > 0 else max(params.generate.ratios)
    index = read_table(gqcnn_dir("original") / "index.parquet")
    changes = []
    for seed in params.gqcnn.seeds:  # per-object AP change per seed, then the mean over seeds
        after, rows = predictions("targeted", base, compare, seed)
        before, _ = predictions("targeted", base, 0.0, seed)
        labels, shape_ids = index.label.to_numpy()[rows], index.shape_id.to_numpy()[rows]
        changes.append(per_object_ap(labels, after, shape_ids) - per_object_ap(labels, before, shape_ids))
    improvement = pd.concat(changes, axis=1).mean(axis=1).dropna()
    scores = read_table(SCORES).set_index("shape_id")
    base_set = read_table(base_set_table(base))
    generated = read_table(generated_index(base))
    generated = generated[(generated.pool == "targeted") & (generated.order < ratio_count(compare, base))]
    grasps = read_table(grasps_table(f"gen_{base}"))
    generated_graspness = grasps.groupby("shape_id").success.mean().reindex(generated.shape_id).fillna(0.0).to_numpy()
    # test objects' rarity on the same scale as the selected and generated shapes': against the base set
    latents = read_table(LATENTS).set_index("shape_id")
    z_base = np.stack(latents.loc[base_set.shape_id, "z"].to_numpy())
    test_rarity = pd.Series(rarity(z_base, min(params.score.k, len(z_base) - 1), query=np.stack(latents.loc[improvement.index, "z"].to_numpy()))
                            if len(improvement) else [], index=improvement.index, dtype=float)
    panels = improvement_panels(base_set, generated, generated_graspness, test_rarity.to_numpy(),
                                scores.loc[improvement.index, "graspness"].to_numpy(), improvement.to_numpy())
    improvement_by_interval(panels, REPORT_DIR / "improvement_by_score.png",
                            f"B = {base}: per-object test AP, ratio 1:{compare:g} minus 1:0 ({len(improvement)} test objects with both labels)")
    summary["per_object"] = {"base_size": base, "ratio": compare, "objects": int(len(improvement)),
                             "mean_improvement": round(float(improvement.mean()), 5) if len(improvement) else None,
                             "improved_share": round(float((improvement > 0).mean()), 4) if len(improvement) else None}

    # Fig. 1: t-SNE of original train and generated latents by graspness
    from sklearn.manifold import TSNE

    latents = latents.reset_index()
    train = latents[latents.split == "train"]
    z = np.concatenate([np.stack(train.z.to_numpy()), np.stack(generated.z.to_numpy())])
    graspness = np.concatenate([scores.loc[train.shape_id, "graspness"].to_numpy(), generated_graspness])
    groups = ["original train"] * len(train) + [f"generated (B = {base}, targeted)"] * len(generated)
    xy = TSNE(n_components=2, perplexity=min(params.embed.perplexity, (len(z) - 1) / 3), init="pca", random_state=params.seed).fit_transform(z)
    scatter_colored(xy, graspness, groups, REPORT_DIR / "tsne_graspness.png", "t-SNE of the AE-Critic latents, colored by graspness (paper Fig. 1)", "graspness")

    ap = {pool: {str(b): {f"{r:g}": {"mean": None if np.isnan(m) else round(m, 5), "std": None if np.isnan(s) else round(s, 5), "n": int(n)}
                          for r, m, s, n in zip(rows.ratio, rows.ap_mean, rows.ap_std, rows.n)}
                 for b, rows in frame.groupby("base_size")} for pool, frame in table.groupby("pool")}
    write_json({"ap": ap, "summary": summary, "seeds": list(params.gqcnn.seeds)}, AP_METRICS)
    with atomic_path(REPORT_DIR / "report.md") as tmp:
        tmp.write_text(report_markdown(table, words, summary, list(params.gqcnn.seeds), params.gqcnn.train.steps, params.gqcnn.train.batch_size))
    for line in words:
        log.info("report: %s", line)


