"""Stage ``report``: the paper's GQ-CNN experiment in one table, declared contrasts with intervals, figures, words.

Reads every network of every seed (``models/gqcnn/s<seed>/``). Writes ``metrics/ap/<contrast>.json`` (``mean``,
``lo``, ``hi``: the 95% interval over seeds × test objects, the one interval every report quotes) and, in
``reports/gqcnn/``: ``ap.json`` (per declared contrast a :func:`~graspaug.experiments.stats.contrast`, judged by
``draws_low``/``draws_high``; AP per network and object; ``chosen_ratio`` per base size, picked on validation AP),
``ap_table.csv``, ``report.md``, ``decomposition.{md,json}`` (the gap to real shapes step by step, real → recon →
blend → targeted / random, over this run's seeds and test objects), ``ap_vs_ratio.png`` (Fig. 7),
``improvement_by_score.png`` (Fig. 8: per-object AP change of the chosen ratio over 1:0 at the largest base size, by
rarity and graspness interval) and ``tsne_graspness.png`` (Fig. 1); the .md reports open with the profile and corpus
that made them."""

from __future__ import annotations

import logging

from graspaug.experiments.ap import figures
from graspaug.experiments.ap.attribution import combine_draws, decomposition_markdown, losing_step
from graspaug.experiments.ap.numbers import ap_headline, ap_metrics, evaluate_networks, ratio_curves
from graspaug.experiments.ap.words import gain_sentences, report_markdown, training_words, verdict
from graspaug.io.atomic import atomic_path
from graspaug.io.tables import read_table, write_csv, write_json, write_json_files
from graspaug.pipeline.params.base import params_model
from graspaug.pipeline.params.embed import EmbedParams
from graspaug.pipeline.params.generate import GenerateParams
from graspaug.pipeline.params.gqcnn import GQCNNParams
from graspaug.pipeline.params.score import ScoreParams
from graspaug.pipeline.paths import (
    AP_METRICS,
    AP_REPORT,
    LATENTS,
    REPORT_DIR,
    SCORES,
    SHAPES_TABLE,
    base_set_table,
    generated_index,
    gqcnn_dir,
    gqcnn_seed_dir,
    grasps_table,
)
from graspaug.pipeline.provenance import report_header

log = logging.getLogger(__name__)

Params = params_model(
    "The params the `report` stage reads.",
    embed=EmbedParams,
    score=ScoreParams,
    generate=GenerateParams,
    gqcnn=GQCNNParams,
)


def run(params: Params) -> None:
    gen, cfg, seeds, data_seed = params.generate, params.gqcnn, list(params.gqcnn.seeds), params.data_seed
    header = report_header(params.file_text, read_table(SHAPES_TABLE))  # the profile and corpus, on every report
    seed_dirs = {seed: gqcnn_seed_dir(seed) for seed in seeds}
    # a missing network is a DataError, which the CLI prints in one line
    ev = evaluate_networks(seed_dirs, gqcnn_dir("original"), gen, cfg, params.seed)
    table, chosen, results, labels = ev.table, ev.chosen, ev.contrasts, ev.labels
    write_csv(table, REPORT_DIR / "ap_table.csv")
    write_csv(ratio_curves(table), REPORT_DIR / "ap_vs_ratio.csv")  # the curves of ap_vs_ratio.png, one column each
    figures.draw_ap_vs_ratio(table, seeds, REPORT_DIR / "ap_vs_ratio.png")
    # real → recon → blend → targeted / random, step by step, on this run's one draw of the data (the same
    # resamples as evaluate_networks': every contrast and share is quoted with one interval in both reports)
    steps = combine_draws({params.data_seed: seed_dirs}, labels, ev.object_ids, gen, cfg, 1000, params.seed)
    write_json(steps, REPORT_DIR / "decomposition.json")
    extras = gain_sentences(steps["share"], table, chosen, ev.ceiling_shapes if cfg.ceiling else None)
    extras += [losing_step(steps["contrasts"], b) for b in cfg.augment_base_sizes]
    with atomic_path(REPORT_DIR / "decomposition.md") as tmp:
        tmp.write_text(header + decomposition_markdown(steps, cfg.augment_base_sizes, "dvc repro report"))
    # Fig. 8: the largest augmented base size, its ratio chosen on validation against 1:0
    base = max(cfg.augment_base_sizes)
    compare = chosen.get(base, max(gen.ratios))
    # the networks sim compares (and the ceiling): PR and ROC curves of their test predictions
    figures.draw_pr_roc(labels, seed_dirs[seeds[0]], seeds[0], base, compare, cfg.ceiling, REPORT_DIR / "pr_roc.png")
    scores, latents = read_table(SCORES).set_index("shape_id"), read_table(LATENTS).set_index("shape_id")
    base_set, generated = read_table(base_set_table(base)), read_table(generated_index(base))
    grasps = read_table(grasps_table(f"gen_{base}"))
    improvement, augmentation, panels, generated_graspness = figures.improvement_data(
        ev.by_network, seeds, base, compare, base_set, generated, grasps, latents, scores, params.score.k
    )
    figures.draw_improvement(panels, improvement, base, compare, REPORT_DIR / "improvement_by_score.png")
    # Fig. 1: t-SNE of original train and generated latents by graspness
    tsne, perplexity = REPORT_DIR / "tsne_graspness.png", params.embed.perplexity
    figures.draw_latent_map(latents, scores, augmentation, generated_graspness, base, perplexity, params.seed, tsne)
    positives = float(labels.mean())  # the share of positive test grasps: AP without skill
    ap_report = ap_metrics(results, table, chosen, positives, seeds)
    write_json(ap_report, AP_REPORT)
    write_json_files(ap_headline(ap_report), AP_METRICS)
    words = training_words(cfg.train, cfg.members)
    with atomic_path(REPORT_DIR / "report.md") as tmp:
        tmp.write_text(header + report_markdown(table, results, chosen, extras, seeds, positives, words, data_seed))
    for name, c in results.items():
        log.info("report: %s", verdict(name, c))


if __name__ == "__main__":
    from graspaug.pipeline.entry import stage_main

    stage_main(__spec__.name)
