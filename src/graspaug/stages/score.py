"""Stage ``score``: rarity and graspness of every original shape (paper Section III-B).

Rarity is eq. (3)-(4) on the AE-Critic latents relative to the shapes being augmented (the
train split): train shapes are scored among themselves, test shapes against the train
split. Graspness is the share of a shape's sampled grasps whose robust ε exceeds the
threshold (0 for a shape without grasps).

Outputs: ``data/scores.parquet`` (``shape_id``, ``split``, ``rarity``, ``graspness``,
``n_grasps``, ``n_success``), ``metrics/score.json``, and in ``reports/score/``: graspness and
rarity histograms of the train split (CSV + PNG; the graspness one is the paper's Fig. 4) and
``grasp_examples.png`` (low / middle / high graspness shapes with their grasps).
"""

from __future__ import annotations

import logging

import numpy as np
import pandas as pd

from graspaug.io.meshes import mesh_path, read_mesh
from graspaug.io.tables import read_table, write_csv, write_json, write_table
from graspaug.params.base import params_model
from graspaug.params.grasps import GraspsParams
from graspaug.params.score import ScoreParams
from graspaug.paths import (
    GRASP_EXAMPLES_PNG,
    GRASPNESS_HIST_CSV,
    GRASPNESS_HIST_PNG,
    LATENTS,
    RARITY_HIST_CSV,
    RARITY_HIST_PNG,
    SCORE_METRICS,
    SCORES,
    SHAPES_DIR,
    SHAPES_TABLE,
    grasps_table,
)
from graspaug.plots import grasps_on_shapes, histogram
from graspaug.scores import graspness, rarity
from graspaug.stages import StageError

log = logging.getLogger(__name__)

Params = params_model("The params the `score` stage reads.", score=ScoreParams, grasps=GraspsParams)


def shape_scores(shapes: pd.DataFrame, latents: pd.DataFrame, grasps: pd.DataFrame, k: int) -> pd.DataFrame:
    """The scores table, one row per shape of ``shapes`` (``shape_id``, ``split``)."""
    z = latents.set_index("shape_id").z
    missing = sorted(set(shapes.shape_id) - set(z.index))
    if missing:
        raise StageError(f"{len(missing)} shapes have no latent (e.g. {missing[0]}); rerun `dvc repro embed`")
    train = (shapes.split == "train").to_numpy()
    if train.sum() < 2:
        raise StageError(f"rarity needs at least 2 train shapes, found {int(train.sum())}")
    latent = np.stack(z.loc[shapes.shape_id].to_numpy()).astype(float)
    scores = np.empty(len(shapes))
    scores[train] = rarity(latent[train], k)
    if (~train).any():
        scores[~train] = rarity(latent[train], k, query=latent[~train])
    index = pd.Index(shapes.shape_id)
    known = grasps.shape_id.isin(index).to_numpy()
    share, counts = graspness(grasps.success.to_numpy()[known], index.get_indexer(grasps.shape_id[known]), len(shapes))
    wins = np.rint(share * counts).astype(np.int64)
    return pd.DataFrame(
        {
            "shape_id": shapes.shape_id.to_numpy(),
            "split": shapes.split.to_numpy(),
            "rarity": scores,
            "graspness": share,
            "n_grasps": counts,
            "n_success": wins,
        }
    )


def histogram_table(values: np.ndarray, bins: int, lo: float | None = None, hi: float | None = None) -> pd.DataFrame:
    counts, edges = np.histogram(
        values, bins=bins, range=(lo if lo is not None else values.min(), hi if hi is not None else values.max())
    )
    return pd.DataFrame(
        {"bin_left": edges[:-1], "bin_right": edges[1:], "bin_center": 0.5 * (edges[:-1] + edges[1:]), "shapes": counts}
    )


def example_shapes(scores: pd.DataFrame) -> list[str]:
    """Train shapes with grasps at the lowest, middle and highest graspness."""
    ranked = scores[(scores.split == "train") & (scores.n_grasps > 0)].sort_values(["graspness", "shape_id"])
    if ranked.empty:
        return []
    picks = [0, len(ranked) // 2, len(ranked) - 1]
    return list(dict.fromkeys(ranked.shape_id.iloc[picks]))


def _rounded(value: float) -> float | None:
    """A JSON-safe metric: NaN (e.g. a correlation with a constant column) becomes null."""
    return round(float(value), 4) if np.isfinite(value) else None


def run(params: Params) -> None:
    cfg = params.score
    shapes = read_table(SHAPES_TABLE)
    grasps = read_table(grasps_table("original"))
    scores = shape_scores(shapes, read_table(LATENTS), grasps, cfg.k)
    write_table(scores, SCORES)

    train = scores[scores.split == "train"]
    g_hist = histogram_table(train.graspness.to_numpy(), cfg.bins, 0.0, 1.0)
    write_csv(g_hist, GRASPNESS_HIST_CSV)
    histogram(
        g_hist.shapes.to_numpy(),
        np.r_[g_hist.bin_left, g_hist.bin_right.iloc[-1]],
        GRASPNESS_HIST_PNG,
        f"graspness (share of grasps with robust ε > {params.grasps.threshold})",
        f"Graspness of the {len(train)} train shapes",
    )
    r_hist = histogram_table(train.rarity.to_numpy(), cfg.bins)
    write_csv(r_hist, RARITY_HIST_CSV)
    histogram(
        r_hist.shapes.to_numpy(),
        np.r_[r_hist.bin_left, r_hist.bin_right.iloc[-1]],
        RARITY_HIST_PNG,
        f"rarity R, eq. (4), k = {cfg.k}",
        f"Rarity of the {len(train)} train shapes",
    )

    picks = example_shapes(scores)
    if not picks:
        log.warning("score: no train shape has a grasp; the grasp picture is empty")
    drawn = [(read_mesh(mesh_path(SHAPES_DIR, s)), grasps[grasps.shape_id == s]) for s in picks]
    grasps_on_shapes(
        [(m.vertices, m.faces) for m, _ in drawn],
        [
            np.stack([g[["p1_x", "p1_y", "p1_z"]].to_numpy(), g[["p2_x", "p2_y", "p2_z"]].to_numpy()], axis=1)
            for _, g in drawn
        ],
        [g.eps_mean.to_numpy() for _, g in drawn],
        [f"{s}: graspness {scores.set_index('shape_id').graspness[s]:.2f}" for s in picks],
        GRASP_EXAMPLES_PNG,
        vmax=2 * params.grasps.threshold,
        threshold=params.grasps.threshold,
    )
    summary = {
        "n_train": int(len(train)),
        "graspness_train_mean": round(float(train.graspness.mean()), 4),
        "graspness_train_median": round(float(train.graspness.median()), 4),
        "train_shapes_without_success": int((train.n_success == 0).sum()),
        "rarity_train_median": round(float(train.rarity.median()), 4),
        "rarity_train_max": round(float(train.rarity.max()), 4),
        "rarity_graspness_spearman": _rounded(train[["rarity", "graspness"]].corr(method="spearman").iloc[0, 1]),
    }
    write_json(summary, SCORE_METRICS)
    log.info(
        "score: %d shapes; train graspness mean %.3f, rarity median %.3f",
        len(scores),
        summary["graspness_train_mean"],
        summary["rarity_train_median"],
    )
