"""The GQ-CNN report's figures (:mod:`graspaug.experiments.ap` makes their data): each function
draws one figure with its title into the file ``path`` it is given."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from graspaug.experiments.ap import compared_predictions, latent_map


def draw_ap_vs_ratio(table: pd.DataFrame, seeds: list[int], path: Path) -> None:
    """Fig. 7: test AP against the ratio per base size and pool (``table``:
    :func:`~graspaug.experiments.ap.network_table`, over training ``seeds``), 95% t-interval bars."""
    from graspaug.plots import ap_vs_ratio

    ap_vs_ratio(table, path, f"Test AP vs augmentation ratio (seeds {seeds}; error bars: 95% t-interval)")


def draw_pr_roc(
    labels: np.ndarray, seed_dir: Path, seed: int, base_size: int, ratio: float, ceiling: bool, path: Path
) -> None:
    """PR and ROC curves of the test predictions of training seed ``seed`` (folder ``seed_dir``) of the
    networks the robot trials compare (:func:`~graspaug.experiments.ap.compared_predictions`: targeted
    at 1:0 and 1:``ratio`` for ``base_size``, the ceiling when trained) against the test ``labels`` (N,)."""
    from graspaug.plots import precision_recall_roc

    predictions = compared_predictions(seed_dir, base_size, ratio, ceiling)
    precision_recall_roc(labels, predictions, path, f"Test predictions of training seed {seed} ({len(labels)} grasps)")


def draw_improvement(panels: list[dict], improvement: pd.Series, base_size: int, ratio: float, path: Path) -> None:
    """Fig. 8: the per-object test AP change of 1:``ratio`` over 1:0 at ``base_size`` (``improvement``, by
    test object, mean over seeds) by rarity and graspness interval (``panels``:
    :func:`~graspaug.experiments.ap.improvement_data`)."""
    from graspaug.plots import improvement_by_interval

    improvement_by_interval(
        panels,
        path,
        f"B = {base_size}: per-object test AP, 1:{ratio:g} minus 1:0, mean over seeds "
        f"({len(improvement)} test objects with both labels)",
    )


def draw_latent_map(
    latents: pd.DataFrame,
    scores: pd.DataFrame,
    generated: pd.DataFrame,
    generated_graspness: np.ndarray,
    base_size: int,
    perplexity: float,
    seed: int,
    path: Path,
) -> None:
    """Fig. 1: t-SNE of the original train shapes' and the generated shapes' latents colored by
    graspness (:func:`~graspaug.experiments.ap.latent_map`; ``latents`` and ``scores`` by shape id)."""
    from graspaug.plots import scatter_colored

    xy, graspness, groups = latent_map(
        latents.reset_index(), scores, generated, generated_graspness, base_size, perplexity, seed
    )
    scatter_colored(
        xy,
        graspness,
        groups,
        path,
        "t-SNE of the AE-Critic latents, colored by graspness (paper Fig. 1)",
        "graspness",
    )
