"""The ``score`` stage's tables: per-shape rarity and graspness, histograms, examples and metrics."""

from __future__ import annotations

import numpy as np
import pandas as pd

from graspaug.augment.scores import graspness, rarity
from graspaug.errors import DataError


def shape_scores(shapes: pd.DataFrame, latents: pd.DataFrame, grasps: pd.DataFrame, k: int) -> pd.DataFrame:
    """The scores table, one row per shape of ``shapes``, in its order.

    Parameters
    ----------
    shapes : table with ``shape_id`` (str) and ``split`` (``"train"`` / ``"test"``), one row per shape
    latents : table with ``shape_id`` and ``z`` ((d,) float latent of that shape), any order
    grasps : table with ``shape_id`` and ``success`` (bool), one row per grasp; rows of unknown shapes are ignored
    k : neighbours of the rarity, eq. (3)-(4)

    Returns
    -------
    DataFrame with ``shape_id``, ``split``, ``rarity`` (train shapes among themselves, test shapes
    against the train split), ``graspness`` (share of successful grasps, 0 without grasps),
    ``n_grasps`` and ``n_success`` (int64 counts).
    """
    z = latents.set_index("shape_id").z
    missing = sorted(set(shapes.shape_id) - set(z.index))
    if missing:
        raise DataError(f"{len(missing)} shapes have no latent (e.g. {missing[0]}); rerun `dvc repro embed`")
    train = (shapes.split == "train").to_numpy()
    if train.sum() < 2:
        raise DataError(f"rarity needs at least 2 train shapes, found {int(train.sum())}")
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
    """Counts of ``values`` (n,) in ``bins`` equal bins over [``lo``, ``hi``] (default: the values' min / max).

    Returns a table with one row per bin: ``bin_left``, ``bin_right``, ``bin_center`` (in the
    values' unit) and ``shapes`` (count).
    """
    counts, edges = np.histogram(
        values, bins=bins, range=(lo if lo is not None else values.min(), hi if hi is not None else values.max())
    )
    return pd.DataFrame(
        {"bin_left": edges[:-1], "bin_right": edges[1:], "bin_center": 0.5 * (edges[:-1] + edges[1:]), "shapes": counts}
    )


def histogram_bars(table: pd.DataFrame) -> tuple[np.ndarray, np.ndarray]:
    """(counts (B,), edges (B + 1,)) of a :func:`histogram_table`, as :func:`graspaug.plots.histogram` takes them."""
    return table.shapes.to_numpy(), np.r_[table.bin_left, table.bin_right.iloc[-1]]


def example_shapes(scores: pd.DataFrame) -> list[str]:
    """Train shapes with grasps at the lowest, middle and highest graspness (shape ids, no repeats)."""
    ranked = scores[(scores.split == "train") & (scores.n_grasps > 0)].sort_values(["graspness", "shape_id"])
    if ranked.empty:
        return []
    picks = [0, len(ranked) // 2, len(ranked) - 1]
    return list(dict.fromkeys(ranked.shape_id.iloc[picks]))


def grasp_examples(
    meshes: list, grasps: pd.DataFrame, scores: pd.DataFrame, picks: list[str]
) -> tuple[list[tuple[np.ndarray, np.ndarray]], list[np.ndarray], list[np.ndarray], list[str]]:
    """The picture data of :func:`graspaug.plots.grasps_on_shapes` for shapes ``picks``.

    Parameters
    ----------
    meshes : per pick, its mesh (``vertices`` (V, 3) m, ``faces`` (F, 3))
    grasps : grasp table with ``shape_id``, contacts ``p1_x`` … ``p2_z`` (m) and ``eps_mean`` (robust ε)
    scores : the :func:`shape_scores` table
    picks : shape ids

    Returns
    -------
    (shapes, segments, qualities, titles): per pick ``(vertices, faces)``, (G, 2, 3) contact pairs
    (m), (G,) robust ε and a title with its graspness.
    """
    rows = [grasps[grasps.shape_id == s] for s in picks]
    segments = [
        np.stack([g[["p1_x", "p1_y", "p1_z"]].to_numpy(), g[["p2_x", "p2_y", "p2_z"]].to_numpy()], axis=1) for g in rows
    ]
    titles = [f"{s}: graspness {scores.set_index('shape_id').graspness[s]:.2f}" for s in picks]
    return [(m.vertices, m.faces) for m in meshes], segments, [g.eps_mean.to_numpy() for g in rows], titles


def _rounded(value: float) -> float | None:
    """A JSON-safe metric: NaN (e.g. a correlation with a constant column) becomes null."""
    return round(float(value), 4) if np.isfinite(value) else None


def score_summary(train: pd.DataFrame) -> dict:
    """The ``score`` stage's metrics from the train rows of the :func:`shape_scores` table:
    counts, graspness mean / median (share), rarity median / max and their Spearman correlation
    (None when undefined), rounded to 4 decimals."""
    return {
        "n_train": int(len(train)),
        "graspness_train_mean": round(float(train.graspness.mean()), 4),
        "graspness_train_median": round(float(train.graspness.median()), 4),
        "train_shapes_without_success": int((train.n_success == 0).sum()),
        "rarity_train_median": round(float(train.rarity.median()), 4),
        "rarity_train_max": round(float(train.rarity.max()), 4),
        "rarity_graspness_spearman": _rounded(train[["rarity", "graspness"]].corr(method="spearman").iloc[0, 1]),
    }


def score_headline(summary: dict) -> dict:
    """The stage's metrics from its :func:`score_summary`: train ``shapes`` scored and their mean ``graspness``."""
    return {"shapes": summary["n_train"], "graspness": summary["graspness_train_mean"]}
