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

from graspaug.experiments.ap import (
    ap_metrics,
    choose_ratios,
    collect,
    declared_contrasts,
    evaluate_contrasts,
    gain_sentences,
    latent_map,
    network_table,
    object_improvement,
    per_object_aps,
    ratio_curves,
    report_markdown,
    score_panels,
    test_predictions,
    test_rows,
    training_words,
    verdict,
)
from graspaug.experiments.networks import seed_variants
from graspaug.generation import ratio_count
from graspaug.io.atomic import atomic_path
from graspaug.io.tables import read_table, write_csv, write_json
from graspaug.params.base import params_model
from graspaug.params.embed import EmbedParams
from graspaug.params.generate import GenerateParams
from graspaug.params.gqcnn import GQCNNParams
from graspaug.params.score import ScoreParams
from graspaug.paths import (
    AP_METRICS,
    LATENTS,
    REPORT_DIR,
    SCORES,
    base_set_table,
    generated_index,
    gqcnn_dir,
    gqcnn_seed_dir,
    grasps_table,
)

log = logging.getLogger(__name__)

Params = params_model(
    "The params the `report` stage reads.",
    embed=EmbedParams,
    score=ScoreParams,
    generate=GenerateParams,
    gqcnn=GQCNNParams,
)


def run(params: Params) -> None:
    from graspaug.plots import ap_vs_ratio, improvement_by_interval, precision_recall_roc, scatter_colored

    gen, cfg, seeds = params.generate, params.gqcnn, list(params.gqcnn.seeds)
    seed_dirs = {seed: gqcnn_seed_dir(seed) for seed in seeds}
    variants = seed_variants(gen.base_sizes, gen.ratios, cfg.augment_base_sizes, cfg.ceiling)
    runs = collect(seed_dirs, variants)  # a missing network is a DataError, which the CLI prints in one line
    chosen = choose_ratios(runs, cfg.augment_base_sizes)
    contrasts = declared_contrasts(gen.base_sizes, gen.ratios, cfg.augment_base_sizes, chosen)
    index = read_table(gqcnn_dir("original") / "index.parquet")
    rows = test_rows(seed_dirs[seeds[0]])
    labels, object_ids = index.label.to_numpy()[rows], index.shape_id.to_numpy()[rows]
    results = evaluate_contrasts(contrasts, runs, seed_dirs, labels, object_ids, n_resamples=1000, seed=params.seed)
    per_object, by_network = per_object_aps(seed_dirs, variants, labels, object_ids)
    table = network_table(runs, per_object)
    write_csv(table, REPORT_DIR / "ap_table.csv")
    write_csv(ratio_curves(table), REPORT_DIR / "ap_vs_ratio.csv")  # for `dvc plots`
    n_ceiling = len(index[index.split == "train"].shape_id.unique()) - cfg.val_shapes
    extras = gain_sentences(results, table, chosen, cfg.augment_base_sizes, n_ceiling if cfg.ceiling else None)
    ap_vs_ratio(
        table,
        REPORT_DIR / "ap_vs_ratio.png",
        f"Test AP vs augmentation ratio (seeds {seeds}; error bars: 95% t-interval)",
    )

    # Fig. 8: the largest augmented base size, its ratio chosen on validation against 1:0
    base = max(cfg.augment_base_sizes)
    compare = chosen.get(base, max(gen.ratios))
    compared = {
        f"B = {base}, 1:0": ("targeted", base, 0.0),
        f"B = {base}, 1:{compare:g}": ("targeted", base, compare),
        "ceiling": ("ceiling", 0, 0.0),
    }
    # the networks sim compares (and the ceiling): PR and ROC curves of their test predictions
    predictions = {
        name: test_predictions(seed_dirs[seeds[0]], key)
        for name, key in compared.items()
        if cfg.ceiling or key[0] != "ceiling"
    }
    precision_recall_roc(
        labels,
        predictions,
        REPORT_DIR / "pr_roc.png",
        f"Test predictions of training seed {seeds[0]} ({len(labels)} grasps)",
    )
    improvement = object_improvement(by_network, base, compare, seeds)
    scores = read_table(SCORES).set_index("shape_id")
    base_set, generated = read_table(base_set_table(base)), read_table(generated_index(base))
    generated = generated[(generated.pool == "targeted") & (generated.order < ratio_count(compare, base))]
    latents = read_table(LATENTS).set_index("shape_id")
    grasps = read_table(grasps_table(f"gen_{base}"))
    # the test objects' rarity against the base set, as the selected shapes'
    panels, generated_graspness = score_panels(
        improvement, base_set, generated, grasps, latents, scores, params.score.k
    )
    improvement_by_interval(
        panels,
        REPORT_DIR / "improvement_by_score.png",
        f"B = {base}: per-object test AP, 1:{compare:g} minus 1:0, mean over seeds "
        f"({len(improvement)} test objects with both labels)",
    )
    # Fig. 1: t-SNE of original train and generated latents by graspness
    xy, graspness, groups = latent_map(
        latents.reset_index(), scores, generated, generated_graspness, base, params.embed.perplexity, params.seed
    )
    scatter_colored(
        xy,
        graspness,
        groups,
        REPORT_DIR / "tsne_graspness.png",
        "t-SNE of the AE-Critic latents, colored by graspness (paper Fig. 1)",
        "graspness",
    )

    positive_share = float(labels.mean())
    write_json(ap_metrics(results, table, chosen, positive_share, seeds), AP_METRICS)
    with atomic_path(REPORT_DIR / "report.md") as tmp:
        tmp.write_text(
            report_markdown(
                table, results, chosen, extras, seeds, positive_share, training_words(cfg.train, cfg.members)
            )
        )
    for name, c in results.items():
        log.info("report: %s", verdict(name, c))
