"""Stage ``report``: the paper's GQ-CNN experiment in one table, declared contrasts with
intervals, three figures and plain words.

Reads every network of every seed (``models/gqcnn/s<seed>/``). Writes ``metrics/ap.json``
(``contrasts``: per declared contrast ``mean``, ``ci_low``/``ci_high`` (95% t over seeds),
``n_seeds``, ``sd``, ``boot_low``/``boot_high`` (95% bootstrap over test objects); ``networks``:
test / validation / per-object AP per pool, base size, ratio; ``chosen_ratio`` per base size,
picked on validation AP), ``reports/gqcnn/ap_table.csv`` and, in ``reports/gqcnn/``:
``report.md``, ``ap_vs_ratio.png`` (Fig. 7), ``improvement_by_score.png`` (Fig. 8: per-object AP
change of the chosen ratio over 1:0 at the largest base size, by rarity and graspness interval)
and ``tsne_graspness.png`` (Fig. 1).
"""
from __future__ import annotations

import logging

import numpy as np
import pandas as pd

from graspaug.config import Params
from graspaug.experiments.ap import (choose_ratios, collect, declared_contrasts, evaluate_contrasts, gain_sentences, improvement_panels, network_table, per_object_ap, training_words,
                                    report_markdown, test_predictions, test_rows, verdict)
from graspaug.experiments.networks import seed_variants
from graspaug.generation import ratio_count
from graspaug.io.atomic import atomic_path
from graspaug.io.tables import read_table, write_csv, write_json
from graspaug.paths import AP_METRICS, LATENTS, REPORT_DIR, SCORES, base_set_table, generated_index, gqcnn_dir, grasps_table
from graspaug.scores import rarity

log = logging.getLogger(__name__)


def run(params: Params) -> None:
    from graspaug.plots import ap_vs_ratio, improvement_by_interval, precision_recall_roc, scatter_colored

    gen, cfg, seeds = params.generate, params.gqcnn, list(params.gqcnn.seeds)
    variants = seed_variants(gen.base_sizes, gen.ratios, cfg.augment_base_sizes, cfg.ceiling)
    runs = collect(seeds, variants)  # a missing network is a FileNotFoundError, which the CLI prints in one line
    chosen = choose_ratios(runs, cfg.augment_base_sizes)
    contrasts = declared_contrasts(gen.base_sizes, gen.ratios, cfg.augment_base_sizes, chosen)
    index = read_table(gqcnn_dir("original") / "index.parquet")
    rows = test_rows(seeds[0])
    labels, object_ids = index.label.to_numpy()[rows], index.shape_id.to_numpy()[rows]
    results = evaluate_contrasts(contrasts, runs, seeds, labels, object_ids, n_resamples=1000, seed=params.seed)
    per_object, changes = [], {}
    for seed in seeds:
        for v in variants:
            ap = per_object_ap(labels, test_predictions((v.pool, v.base_size, v.ratio), seed), object_ids)
            per_object.append({"pool": v.pool, "base_size": v.base_size, "ratio": float(v.ratio), "seed": seed, "per_object_ap": ap.mean()})
            changes[v.pool, v.base_size, float(v.ratio), seed] = ap
    table = network_table(runs, pd.DataFrame(per_object))
    write_csv(table, REPORT_DIR / "ap_table.csv")
    curves_table = table[table.pool != "ceiling"].assign(curve=lambda t: t.pool + "_" + t.base_size.astype(str))
    write_csv(curves_table.pivot(index="ratio", columns="curve", values="test_ap").reset_index(), REPORT_DIR / "ap_vs_ratio.csv")  # for `dvc plots`
    n_ceiling = len(index[index.split == "train"].shape_id.unique()) - cfg.val_shapes
    extras = gain_sentences(results, table, chosen, cfg.augment_base_sizes, n_ceiling if cfg.ceiling else None)
    ap_vs_ratio(table, REPORT_DIR / "ap_vs_ratio.png", f"Test AP vs augmentation ratio (seeds {seeds}; error bars: 95% t-interval)")

    # Fig. 8: the largest augmented base size, its ratio chosen on validation against 1:0
    base = max(cfg.augment_base_sizes)
    compare = chosen.get(base, max(gen.ratios))
    compared = {f"B = {base}, 1:0": ("targeted", base, 0.0), f"B = {base}, 1:{compare:g}": ("targeted", base, compare), "ceiling": ("ceiling", 0, 0.0)}
    # the networks sim compares (and the ceiling): PR and ROC curves of their test predictions
    precision_recall_roc(labels, {name: test_predictions(key, seeds[0]) for name, key in compared.items() if cfg.ceiling or key[0] != "ceiling"},
                         REPORT_DIR / "pr_roc.png", f"Test predictions of training seed {seeds[0]} ({len(labels)} grasps)")
    improvement = pd.concat([changes["targeted", base, compare, s] - changes["targeted", base, 0.0, s] for s in seeds], axis=1).mean(axis=1).dropna()
    scores = read_table(SCORES).set_index("shape_id")
    base_set, generated = read_table(base_set_table(base)), read_table(generated_index(base))
    generated = generated[(generated.pool == "targeted") & (generated.order < ratio_count(compare, base))]
    grasps = read_table(grasps_table(f"gen_{base}"))
    generated_graspness = grasps.groupby("shape_id").success.mean().reindex(generated.shape_id).fillna(0.0).to_numpy()
    latents = read_table(LATENTS).set_index("shape_id")  # test objects' rarity against the base set, as the selected shapes'
    z_base = np.stack(latents.loc[base_set.shape_id, "z"].to_numpy())
    test_rarity = rarity(z_base, min(params.score.k, len(z_base) - 1), query=np.stack(latents.loc[improvement.index, "z"].to_numpy())) \
        if len(improvement) else np.zeros(0)
    panels = improvement_panels(base_set, generated, generated_graspness, np.asarray(test_rarity), scores.loc[improvement.index, "graspness"].to_numpy(),
                                improvement.to_numpy())
    improvement_by_interval(panels, REPORT_DIR / "improvement_by_score.png",
                            f"B = {base}: per-object test AP, 1:{compare:g} minus 1:0, mean over seeds ({len(improvement)} test objects with both labels)")

    from sklearn.manifold import TSNE  # Fig. 1: t-SNE of original train and generated latents by graspness

    latents = latents.reset_index()
    train = latents[latents.split == "train"]
    z = np.concatenate([np.stack(train.z.to_numpy()), np.stack(generated.z.to_numpy())])
    graspness = np.concatenate([scores.loc[train.shape_id, "graspness"].to_numpy(), generated_graspness])
    groups = ["original train"] * len(train) + [f"generated (B = {base}, targeted)"] * len(generated)
    xy = TSNE(n_components=2, perplexity=min(params.embed.perplexity, (len(z) - 1) / 3), init="pca", random_state=params.seed).fit_transform(z)
    scatter_colored(xy, graspness, groups, REPORT_DIR / "tsne_graspness.png", "t-SNE of the AE-Critic latents, colored by graspness (paper Fig. 1)", "graspness")

    positive_share = float(labels.mean())
    networks = {pool: {str(b): {f"{r:g}": {k: (None if v is None or not np.isfinite(v) else round(float(v), 5)) for k, v in row.items()}
                                for r, row in g.set_index("ratio")[["test_ap", "test_ap_ci", "per_object_ap", "val_ap"]].iterrows()}
                       for b, g in frame.groupby("base_size")} for pool, frame in table.groupby("pool")}
    write_json({"contrasts": results, "networks": networks, "chosen_ratio": {str(b): r for b, r in chosen.items()},
                "summary": {str(b): {"best_ratio": r, "chosen_on": "validation AP"} for b, r in chosen.items()},
                "test_positive_share": round(positive_share, 5), "seeds": seeds}, AP_METRICS)
    with atomic_path(REPORT_DIR / "report.md") as tmp:
        tmp.write_text(report_markdown(table, results, chosen, extras, seeds, positive_share, training_words(cfg.train, cfg.members)))
    for name, c in results.items():
        log.info("report: %s", verdict(name, c))
