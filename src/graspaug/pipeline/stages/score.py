"""Stage ``score``: rarity and graspness of every original shape (paper Section III-B).

Rarity is eq. (3)-(4) on the AE-Critic latents relative to the shapes being augmented (the
train split): train shapes are scored among themselves, test shapes against the train
split. Graspness is the share of a shape's sampled grasps whose robust ε exceeds the
threshold (0 for a shape without grasps).

Outputs: ``data/scores.parquet`` (``shape_id``, ``split``, ``rarity``, ``graspness``,
``n_grasps``, ``n_success``), ``metrics/score.json`` (train shapes, mean graspness), and in ``reports/score/``:
``summary.json`` (every figure of the train split), graspness and
rarity histograms of the train split (CSV + PNG; the graspness one is the paper's Fig. 4) and
``grasp_examples.png`` (low / middle / high graspness shapes with their grasps).
"""

from __future__ import annotations

import logging

from graspaug.augment.score_tables import (
    example_shapes,
    grasp_examples,
    histogram_bars,
    histogram_table,
    score_headline,
    score_summary,
    shape_scores,
)
from graspaug.io.meshes import mesh_path, read_mesh
from graspaug.io.tables import read_table, write_csv, write_json, write_table
from graspaug.pipeline.params.base import params_model
from graspaug.pipeline.params.grasps import GraspsParams
from graspaug.pipeline.params.score import ScoreParams
from graspaug.pipeline.paths import (
    GRASP_EXAMPLES_PNG,
    GRASPNESS_HIST_CSV,
    GRASPNESS_HIST_PNG,
    LATENTS,
    RARITY_HIST_CSV,
    RARITY_HIST_PNG,
    SCORE_METRICS,
    SCORE_SUMMARY,
    SCORES,
    SHAPES_DIR,
    SHAPES_TABLE,
    grasps_table,
)
from graspaug.plots import grasps_on_shapes, histogram

log = logging.getLogger(__name__)

Params = params_model("The params the `score` stage reads.", score=ScoreParams, grasps=GraspsParams)


def run(params: Params) -> None:
    cfg, threshold = params.score, params.grasps.threshold
    shapes = read_table(SHAPES_TABLE)
    grasps = read_table(grasps_table("original"))
    scores = shape_scores(shapes, read_table(LATENTS), grasps, cfg.k)
    write_table(scores, SCORES)

    train = scores[scores.split == "train"]
    g_hist = histogram_table(train.graspness.to_numpy(), cfg.bins, 0.0, 1.0)
    write_csv(g_hist, GRASPNESS_HIST_CSV)
    g_label = f"graspness (share of grasps with robust ε > {threshold})"
    histogram(*histogram_bars(g_hist), GRASPNESS_HIST_PNG, g_label, f"Graspness of the {len(train)} train shapes")
    r_hist = histogram_table(train.rarity.to_numpy(), cfg.bins)
    write_csv(r_hist, RARITY_HIST_CSV)
    r_label = f"rarity R, eq. (4), k = {cfg.k}"
    histogram(*histogram_bars(r_hist), RARITY_HIST_PNG, r_label, f"Rarity of the {len(train)} train shapes")

    picks = example_shapes(scores)
    if not picks:
        log.warning("score: no train shape has a grasp; the grasp picture is empty")
    meshes = [read_mesh(mesh_path(SHAPES_DIR, s)) for s in picks]
    pictures = grasp_examples(meshes, grasps, scores, picks)
    grasps_on_shapes(*pictures, GRASP_EXAMPLES_PNG, vmax=2 * threshold, threshold=threshold)
    summary = score_summary(train)
    write_json(summary, SCORE_SUMMARY)
    write_json(score_headline(summary), SCORE_METRICS)
    log.info(
        "score: %d shapes; train graspness mean %.3f, rarity median %.3f",
        len(scores),
        summary["graspness_train_mean"],
        summary["rarity_train_median"],
    )


if __name__ == "__main__":
    from graspaug.pipeline.entry import stage_main

    stage_main(__spec__.name)
