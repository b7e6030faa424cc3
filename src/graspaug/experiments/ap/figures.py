"""The GQ-CNN report's figures: what each draws (the panels, the improvement by score, the latent map), and the
``draw_*`` functions, each drawing one figure with its title into the file ``path`` it is given."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from graspaug.experiments.ap.numbers import object_improvement, test_predictions

#: The range Average Precision lives in: intervals are clipped to it and the AP axis stays within it.
AP_RANGE = (0.0, 1.0)
POOLS_DRAWN = ("targeted", "random", "real", "recon")  # the pools Fig. 7 draws, in this order


def _interval(rows: pd.DataFrame) -> dict[str, np.ndarray]:
    """``rows``' test AP (n,) and its 95% t-interval (``test_ap_ci`` half-width; none: the point) clipped to
    :data:`AP_RANGE`: ``{"ap", "low", "high"}``, each (n,) float."""
    ap = rows.test_ap.to_numpy(dtype=float)
    half = np.nan_to_num(rows.test_ap_ci.to_numpy(dtype=float))
    return {"ap": ap, "low": np.clip(ap - half, *AP_RANGE), "high": np.clip(ap + half, *AP_RANGE)}


def ratio_panels(table: pd.DataFrame) -> dict:
    """What Fig. 7 draws of ``table`` (:func:`~graspaug.experiments.ap.numbers.network_table`).

    One panel per base size B with augmented networks (a ratio > 0): per pool of :data:`POOLS_DRAWN` a curve of test
    AP against ratio R starting from B alone at R = 0, with its interval. A base size with only R = 0 (the positive
    control's larger base set) has no curve of its own: it is a horizontal ``reference`` (a line and its band) on
    every panel, as is the ceiling (every train shape). Without any augmented base size there is one panel of AP
    against B. Every interval is clipped to :data:`AP_RANGE`, and ``ylim`` (low, high) spans what is drawn with a
    margin, within :data:`AP_RANGE`.

    Returns ``{"panels": [{"title", "xlabel", "curves": [{"pool", "x": (n,), "ap", "low", "high"}],
    "references": [{"label", "ap", "low", "high"}]}], "ylim": (low, high)}``, AP values as floats in [0, 1].
    """
    networks = table[(table.pool != "ceiling") & np.isfinite(table.test_ap.to_numpy(dtype=float))]
    augmented = sorted(networks.base_size[networks.ratio > 0].unique())
    references = []
    for base in sorted(set(networks.base_size) - set(augmented)):
        alone = _interval(networks[(networks.base_size == base) & (networks.ratio == 0)].head(1))
        references.append({"label": f"B = {base} alone (R = 0)", **{k: float(v[0]) for k, v in alone.items()}})
    ceiling = table[(table.pool == "ceiling") & np.isfinite(table.test_ap.to_numpy(dtype=float))]
    if len(ceiling):
        top = _interval(ceiling.head(1))
        references.append({"label": "ceiling (all train shapes)", **{k: float(v[0]) for k, v in top.items()}})
    panels = []
    for base in augmented:
        rows = networks[networks.base_size == base]
        alone = rows[rows.ratio == 0].head(1)
        curves = []
        for pool in POOLS_DRAWN:
            added = rows[(rows.pool == pool) & (rows.ratio > 0)]
            if len(added):
                curve = pd.concat([alone, added]).sort_values("ratio")
                curves.append({"pool": pool, "x": curve.ratio.to_numpy(dtype=float), **_interval(curve)})
        panels.append(
            {"title": f"B = {base}", "xlabel": "ratio R (generated : base)", "curves": curves, "references": references}
        )
    if not panels:  # no augmented networks: AP against the base size, the references' own axis
        alone = networks[networks.ratio == 0].drop_duplicates("base_size").sort_values("base_size")
        curve = {"pool": "base set alone", "x": alone.base_size.to_numpy(dtype=float), **_interval(alone)}
        ceiling_only = [r for r in references if r["label"].startswith("ceiling")]
        panels.append(
            {
                "title": "no augmented networks",
                "xlabel": "base set size B (R = 0)",
                "curves": [curve],
                "references": ceiling_only,
            }
        )
    lows = [v for p in panels for c in p["curves"] for v in c["low"]] + [r["low"] for r in references]
    highs = [v for p in panels for c in p["curves"] for v in c["high"]] + [r["high"] for r in references]
    if not lows:
        return {"panels": panels, "ylim": AP_RANGE}
    low, high = min(lows), max(highs)
    margin = max(0.05 * (high - low), 0.02)
    return {"panels": panels, "ylim": (max(AP_RANGE[0], low - margin), min(AP_RANGE[1], high + margin))}


def draw_ap_vs_ratio(table: pd.DataFrame, seeds: list[int], path: Path) -> None:
    """Fig. 7: test AP against the ratio per augmented base size and pool (``table``:
    :func:`~graspaug.experiments.ap.numbers.network_table`, over training ``seeds``), 95% t-interval bars clipped to
    [0, 1], base sizes without augmented networks as reference lines (:func:`ratio_panels`)."""
    from graspaug.plots import ap_vs_ratio

    ap_vs_ratio(
        ratio_panels(table),
        path,
        f"Test AP vs augmentation ratio (seeds {seeds}; error bars: 95% t-interval, clipped to [0, 1])",
    )


def draw_pr_roc(
    labels: np.ndarray, seed_dir: Path, seed: int, base_size: int, ratio: float, ceiling: bool, path: Path
) -> None:
    """PR and ROC curves of the test predictions of training seed ``seed`` (folder ``seed_dir``) of the
    networks the robot trials compare (:func:`~graspaug.experiments.ap.figures.compared_predictions`: targeted
    at 1:0 and 1:``ratio`` for ``base_size``, the ceiling when trained) against the test ``labels`` (N,)."""
    from graspaug.plots import precision_recall_roc

    predictions = compared_predictions(seed_dir, base_size, ratio, ceiling)
    precision_recall_roc(labels, predictions, path, f"Test predictions of training seed {seed} ({len(labels)} grasps)")


def draw_improvement(panels: list[dict], improvement: pd.Series, base_size: int, ratio: float, path: Path) -> None:
    """Fig. 8: the per-object test AP change of 1:``ratio`` over 1:0 at ``base_size`` (``improvement``, by
    test object, mean over seeds) by rarity and graspness interval (``panels``:
    :func:`~graspaug.experiments.ap.figures.improvement_data`)."""
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
    graspness (:func:`~graspaug.experiments.ap.figures.latent_map`; ``latents`` and ``scores`` by shape id)."""
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


def improvement_panels(
    base_set: pd.DataFrame,
    generated: pd.DataFrame,
    generated_graspness: np.ndarray,
    test_rarity: np.ndarray,
    test_graspness: np.ndarray,
    improvement: np.ndarray,
) -> list[dict]:
    """Fig. 8's two panels (rarity against the base set, graspness): bin edges, the selected and
    generated shapes' scores, and the mean per-object AP change of the test objects per bin."""
    panels = []
    for name, selected, made, test_values in (
        (
            "rarity (against the base set)",
            base_set.rarity[base_set.selected_by_rarity],
            generated.rarity_vs_base,
            test_rarity,
        ),
        (
            "graspness",
            base_set.graspness[base_set.selected_by_graspness],
            pd.Series(generated_graspness),
            test_graspness,
        ),
    ):
        values = np.concatenate([selected, made, test_values])
        edges = np.linspace(
            0.0 if name == "graspness" else float(np.min(values)), float(np.quantile(values, 0.99)) + 1e-9, 9
        )
        test_values = np.clip(test_values, edges[0], edges[-1])
        bins = np.clip(np.digitize(test_values, edges) - 1, 0, len(edges) - 2)
        means = [float(improvement[bins == b].mean()) if (bins == b).any() else np.nan for b in range(len(edges) - 1)]
        panels.append(
            {
                "name": name,
                "edges": edges,
                "selected": np.asarray(selected),
                "generated": np.asarray(made),
                "improvement": means,
                "objects": [int((bins == b).sum()) for b in range(len(edges) - 1)],
            }
        )
    return panels


def compared_predictions(seed_dir: Path, base_size: int, ratio: float, ceiling: bool) -> dict[str, np.ndarray]:
    """The test predictions (N,) P(success) of the networks the robot trials compare, by label, of the
    seed in ``seed_dir``: targeted at 1:0 and 1:``ratio`` for ``base_size``, and the ceiling when
    trained (``ceiling``)."""
    compared = {
        f"B = {base_size}, 1:0": ("targeted", base_size, 0.0),
        f"B = {base_size}, 1:{ratio:g}": ("targeted", base_size, ratio),
        "ceiling": ("ceiling", 0, 0.0),
    }
    return {name: test_predictions(seed_dir, key) for name, key in compared.items() if ceiling or key[0] != "ceiling"}


def augmentation_set(generated: pd.DataFrame, base_size: int, ratio: float) -> pd.DataFrame:
    """The rows of the generated index ``generated`` (of base size ``base_size``) that the targeted
    network at 1:``ratio`` trains on: the targeted pool's first ``ratio_count(ratio, base_size)``."""
    from graspaug.augment.candidates import ratio_count

    return generated[(generated.pool == "targeted") & (generated.order < ratio_count(ratio, base_size))]


def score_panels(
    improvement: pd.Series,
    base_set: pd.DataFrame,
    generated: pd.DataFrame,
    grasps: pd.DataFrame,
    latents: pd.DataFrame,
    scores: pd.DataFrame,
    k: int,
) -> tuple[list[dict], np.ndarray]:
    """Fig. 8's panels (:func:`improvement_panels`) of the per-object AP change ``improvement`` (by test
    object): the test objects' rarity against the base set (as the selected shapes', ``k`` neighbours)
    and graspness. ``base_set``: the base set with its scores; ``generated``: the augmentation set's
    rows of the generated index; ``grasps``: the generated shapes' grasps (``shape_id``, ``success``);
    ``latents``, ``scores``: by shape id. Also returns the generated shapes' graspness (share of
    successful grasps, 0 without grasps)."""
    from graspaug.augment.scores import rarity

    generated_graspness = grasps.groupby("shape_id").success.mean().reindex(generated.shape_id).fillna(0.0).to_numpy()
    z_base = np.stack(latents.loc[base_set.shape_id, "z"].to_numpy())
    test_rarity = (
        rarity(z_base, min(k, len(z_base) - 1), query=np.stack(latents.loc[improvement.index, "z"].to_numpy()))
        if len(improvement)
        else np.zeros(0)
    )
    panels = improvement_panels(
        base_set,
        generated,
        generated_graspness,
        np.asarray(test_rarity),
        scores.loc[improvement.index, "graspness"].to_numpy(),
        improvement.to_numpy(),
    )
    return panels, generated_graspness


def improvement_data(
    by_network: dict[tuple, pd.Series],
    seeds,
    base_size: int,
    ratio: float,
    base_set: pd.DataFrame,
    generated: pd.DataFrame,
    grasps: pd.DataFrame,
    latents: pd.DataFrame,
    scores: pd.DataFrame,
    k: int,
) -> tuple[pd.Series, pd.DataFrame, list[dict], np.ndarray]:
    """Fig. 8's data: the per-object AP change of 1:``ratio`` over 1:0 at ``base_size``
    (:func:`object_improvement`), the augmentation set (:func:`augmentation_set` of the generated
    index ``generated``), its panels and the generated shapes' graspness (:func:`score_panels`;
    the test objects' rarity against the base set, as the selected shapes', ``k`` neighbours)."""
    improvement = object_improvement(by_network, base_size, ratio, seeds)
    augmentation = augmentation_set(generated, base_size, ratio)
    panels, generated_graspness = score_panels(improvement, base_set, augmentation, grasps, latents, scores, k)
    return improvement, augmentation, panels, generated_graspness


def latent_map(
    latents: pd.DataFrame,
    scores: pd.DataFrame,
    generated: pd.DataFrame,
    generated_graspness: np.ndarray,
    base_size: int,
    perplexity: float,
    seed: int,
) -> tuple[np.ndarray, np.ndarray, list[str]]:
    """Fig. 1: t-SNE (N, 2) of the original train shapes' and the generated shapes' latents, their
    graspness (N,) and group names. ``latents`` (``shape_id``, ``split``, ``z``), ``scores`` (by
    shape id): of the original shapes; ``generated``: the augmentation set of base size ``base_size``."""
    from sklearn.manifold import TSNE

    train = latents[latents.split == "train"]
    z = np.concatenate([np.stack(train.z.to_numpy()), np.stack(generated.z.to_numpy())])
    graspness = np.concatenate([scores.loc[train.shape_id, "graspness"].to_numpy(), generated_graspness])
    groups = ["original train"] * len(train) + [f"generated (B = {base_size}, targeted)"] * len(generated)
    xy = TSNE(
        n_components=2, perplexity=min(perplexity, (len(z) - 1) / 3), init="pca", random_state=seed
    ).fit_transform(z)
    return xy, graspness, groups
