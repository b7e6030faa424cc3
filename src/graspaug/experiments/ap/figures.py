"""The GQ-CNN report's figures, each in one place: what it draws (its data: the panels, the improvement by score,
the latent map), its drawing (matplotlib, over the primitives of :mod:`graspaug.plots`) and its ``draw_*`` function,
which draws it with its title into the file ``path`` it is given:

- Fig. 7, AP against the ratio: :func:`ratio_panels`, :func:`ap_vs_ratio`, :func:`draw_ap_vs_ratio`;
- PR and ROC curves: :func:`compared_predictions`, :func:`precision_recall_roc`, :func:`draw_pr_roc`;
- Fig. 8, the improvement by score: :func:`improvement_data`, :func:`improvement_by_interval`,
  :func:`draw_improvement`;
- Fig. 1, the latent map: :func:`latent_map`, :func:`scatter_colored`, :func:`draw_latent_map`.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path

import numpy as np
import pandas as pd

from graspaug.experiments.ap.numbers import object_improvement, test_predictions
from graspaug.plots import pyplot, save_figure

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


def ap_vs_ratio(figure: dict, path: str | os.PathLike, title: str) -> None:
    """The paper's Fig. 7 as :func:`graspaug.experiments.ap.figures.ratio_panels` lays it out (``figure``): one panel
    per augmented base size, one line per pool (targeted solid, random dashed, real dotted, recon dash-dotted) with
    its interval as error bars, each reference (a base size alone, the ceiling) a horizontal line with its band on
    every panel; the AP axis ``figure["ylim"]``, shared."""
    plt = pyplot()
    panels = figure["panels"]
    fig, axes = plt.subplots(
        1, len(panels), figsize=(3.6 * len(panels) + 0.8, 3.8), sharey=True, squeeze=False, layout="constrained"
    )
    styles = {
        "targeted": ("-", "tab:blue"),
        "random": ("--", "tab:orange"),
        "real": (":", "tab:green"),
        "recon": ("-.", "tab:purple"),
    }
    reference_colors = ["tab:brown", "tab:pink", "tab:olive", "tab:cyan"]
    for ax, panel in zip(axes[0], panels):
        for curve in panel["curves"]:
            style, color = styles.get(curve["pool"], ("-", "tab:blue"))
            ax.errorbar(
                curve["x"],
                curve["ap"],
                yerr=np.stack([curve["ap"] - curve["low"], curve["high"] - curve["ap"]]),  # (2, n), clipped
                marker="o",
                markersize=4,
                capsize=3,
                linestyle=style,
                color=color,
                label=curve["pool"],
            )
        others = iter(reference_colors)
        for ref in panel["references"]:
            color = "grey" if ref["label"].startswith("ceiling") else next(others, "black")
            ax.axhline(ref["ap"], color=color, linewidth=1, linestyle=(0, (6, 2)), label=ref["label"])
            ax.axhspan(ref["low"], ref["high"], color=color, alpha=0.12, linewidth=0)
        ax.set_title(panel["title"], fontsize=9)
        ax.set_xlabel(panel["xlabel"])
        xs = sorted({float(v) for c in panel["curves"] for v in c["x"]})
        if xs:
            ax.set_xticks(xs)
            pad = 0.08 * (xs[-1] - xs[0]) if xs[-1] > xs[0] else 0.5
            ax.set_xlim(xs[0] - pad, xs[-1] + pad)
        ax.grid(alpha=0.3)
    axes[0, 0].set_ylim(*figure["ylim"])
    axes[0, 0].set_ylabel("test Average Precision")
    legend = {}  # every label once, from whichever panel has it
    for ax in axes[0]:
        for handle, label in zip(*ax.get_legend_handles_labels()):
            legend.setdefault(label, handle)
    axes[0, 0].legend(legend.values(), legend.keys(), fontsize=7, loc="best")
    fig.suptitle(title, fontsize=9)
    save_figure(fig, path)


def draw_ap_vs_ratio(table: pd.DataFrame, seeds: list[int], path: Path) -> None:
    """Fig. 7: test AP against the ratio per augmented base size and pool (``table``:
    :func:`~graspaug.experiments.ap.numbers.network_table`, over training ``seeds``), 95% t-interval bars clipped to
    [0, 1], base sizes without augmented networks as reference lines (:func:`ratio_panels`)."""
    ap_vs_ratio(
        ratio_panels(table),
        path,
        f"Test AP vs augmentation ratio (seeds {seeds}; error bars: 95% t-interval, clipped to [0, 1])",
    )


def precision_recall_roc(
    labels: np.ndarray, predictions: dict[str, np.ndarray], path: str | os.PathLike, title: str
) -> None:
    """Precision-recall (left) and ROC (right) curves of several networks' test predictions
    P(success) (N,) against the same 0/1 ``labels`` (N,); AP and ROC AUC in the legends. With
    one class in ``labels`` there are no curves: the panels say so."""
    from sklearn.metrics import average_precision_score, precision_recall_curve, roc_auc_score, roc_curve

    plt = pyplot()
    fig, (pr, roc) = plt.subplots(1, 2, figsize=(11, 4.5))
    labels = np.asarray(labels).astype(int)
    both = 0 < labels.sum() < len(labels)
    for ax in (pr, roc) if not both else ():
        ax.text(0.5, 0.5, "one class in the test labels: no curve", ha="center", va="center")
    for name, p in predictions.items() if both else ():
        precision, recall, _ = precision_recall_curve(labels, p)
        pr.plot(recall, precision, label=f"{name} (AP {average_precision_score(labels, p):.3f})")
        fpr, tpr, _ = roc_curve(labels, p)
        roc.plot(fpr, tpr, label=f"{name} (AUC {roc_auc_score(labels, p):.3f})")
    pr.axhline(labels.mean(), color="gray", ls=":", label=f"chance ({labels.mean():.3f})")
    roc.plot([0, 1], [0, 1], color="gray", ls=":", label="chance")
    for ax, (x, y) in ((pr, ("recall", "precision")), (roc, ("false positive rate", "true positive rate"))):
        ax.set_xlabel(x)
        ax.set_ylabel(y)
        ax.set_xlim(0, 1)
        ax.set_ylim(0, 1.02)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle(title)
    save_figure(fig, path)


def draw_pr_roc(
    labels: np.ndarray, seed_dir: Path, seed: int, base_size: int, ratio: float, ceiling: bool, path: Path
) -> None:
    """PR and ROC curves of the test predictions of training seed ``seed`` (folder ``seed_dir``) of the
    networks the robot trials compare (:func:`~graspaug.experiments.ap.figures.compared_predictions`: targeted
    at 1:0 and 1:``ratio`` for ``base_size``, the ceiling when trained) against the test ``labels`` (N,)."""
    predictions = compared_predictions(seed_dir, base_size, ratio, ceiling)
    precision_recall_roc(labels, predictions, path, f"Test predictions of training seed {seed} ({len(labels)} grasps)")


def improvement_by_interval(panels: list[dict], path: str | os.PathLike, title: str) -> None:
    """The paper's Fig. 8: per panel (a score: rarity or graspness), normalized histograms of
    the selected and the generated shapes and the mean per-object AP improvement of test
    objects in each score interval. Each panel: ``name``, ``edges`` (bins + 1), ``selected``,
    ``generated`` (score arrays), ``improvement`` (mean per bin, NaN where empty), ``objects`` (per bin)."""
    plt = pyplot()
    fig, axes = plt.subplots(1, len(panels), figsize=(6 * len(panels), 4.2), squeeze=False)
    for ax, panel in zip(axes[0], panels):
        edges = np.asarray(panel["edges"])
        centers, width = (edges[:-1] + edges[1:]) / 2, np.diff(edges)
        for name, values, color in (
            ("selected", panel["selected"], "tab:orange"),
            ("generated", panel["generated"], "tab:green"),
        ):
            counts, _ = np.histogram(np.clip(values, edges[0], edges[-1]), bins=edges)
            share = counts / max(counts.sum(), 1)
            ax.bar(centers, share, width=width * 0.9, alpha=0.45, color=color, label=f"{name} shapes ({len(values)})")
        ax.set_xlabel(panel["name"])
        ax.set_ylabel("share of shapes")
        twin = ax.twinx()
        improvement = np.asarray(panel["improvement"], dtype=float)
        twin.plot(centers, improvement, marker="o", color="tab:blue", label="mean AP improvement of test objects")
        for x, y, n in zip(centers, improvement, panel["objects"]):
            if np.isfinite(y):
                twin.annotate(
                    str(n), (x, y), textcoords="offset points", xytext=(0, 5), ha="center", fontsize=7, color="tab:blue"
                )
        twin.axhline(0, color="gray", linewidth=0.8)
        twin.set_ylabel("per-object AP improvement")
        lines, labels = ax.get_legend_handles_labels()
        more, more_labels = twin.get_legend_handles_labels()
        ax.legend(lines + more, labels + more_labels, fontsize=7, loc="upper left")
    fig.suptitle(title, fontsize=9)
    fig.subplots_adjust(wspace=0.45)
    save_figure(fig, path)


def draw_improvement(panels: list[dict], improvement: pd.Series, base_size: int, ratio: float, path: Path) -> None:
    """Fig. 8: the per-object test AP change of 1:``ratio`` over 1:0 at ``base_size`` (``improvement``, by
    test object, mean over seeds) by rarity and graspness interval (``panels``:
    :func:`~graspaug.experiments.ap.figures.improvement_data`)."""
    improvement_by_interval(
        panels,
        path,
        f"B = {base_size}: per-object test AP, 1:{ratio:g} minus 1:0, mean over seeds "
        f"({len(improvement)} test objects with both labels)",
    )


def scatter_colored(
    xy: np.ndarray, values: np.ndarray, markers: Sequence[str], path: str | os.PathLike, title: str, colorbar: str
) -> None:
    """(N, 2) points colored by ``values``, one marker style per group in ``markers`` (the paper's Fig. 1)."""
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(6.5, 6))
    markers = np.asarray(markers)
    styles = ["o", "^", "s", "D"]
    art = None
    for style, name in zip(styles, sorted(set(markers))):
        sel = markers == name
        art = ax.scatter(
            xy[sel, 0],
            xy[sel, 1],
            c=values[sel],
            s=10 if style == "o" else 16,
            marker=style,
            cmap="viridis",
            vmin=float(np.nanmin(values)),
            vmax=float(np.nanmax(values)),
            label=f"{name} ({sel.sum()})",
            edgecolors="none",
        )
    if art is not None:
        fig.colorbar(art, ax=ax, label=colorbar)
    ax.set_title(title, fontsize=9)
    ax.set_xticks([])
    ax.set_yticks([])
    ax.legend(fontsize=8)
    save_figure(fig, path)


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
