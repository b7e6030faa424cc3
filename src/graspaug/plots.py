"""Figures as PNG files (matplotlib, Agg backend): what the stages show a person.

The shared primitives (lines with bands, bars, scatter maps, voxel and mesh rows, depth crops, pick stories): over
400 lines because each is a small function that several stages' figures call; what an experiment draws is decided in
its own ``figures`` module (``experiments/<name>/figures.py``)."""

from __future__ import annotations

import os
from collections.abc import Sequence

import numpy as np
import pandas as pd

from graspaug.io.atomic import atomic_path


def pyplot():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


DPI = 110  # pixels per inch of every saved figure


def save_figure(fig, path: str | os.PathLike) -> None:
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=DPI, bbox_inches="tight", format="png")
    pyplot().close(fig)


def scatter_2d(xy: np.ndarray, groups: Sequence[str], path: str | os.PathLike, title: str) -> None:
    """(N, 2) points colored by group label (e.g. the t-SNE map by split)."""
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(6, 6))
    groups = np.asarray(groups)
    for name in sorted(set(groups)):
        sel = groups == name
        ax.scatter(xy[sel, 0], xy[sel, 1], s=8, alpha=0.7, label=f"{name} ({sel.sum()})")
    ax.set_title(title)
    ax.set_xticks([])
    ax.set_yticks([])
    ax.legend()
    save_figure(fig, path)


def lines(
    x: Sequence[float],
    series: dict[str, Sequence[float]],
    path: str | os.PathLike,
    xlabel: str,
    ylabel: str,
    title: str,
    intervals: dict[str, tuple[Sequence[float], Sequence[float]]] | None = None,
) -> None:
    """One line per series over shared x values; ``intervals`` (low, high) per series are drawn as bands."""
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(6, 4))
    for name, y in series.items():
        (line,) = ax.plot(x, y, marker="o", label=name)
        if intervals and name in intervals:
            ax.fill_between(x, *intervals[name], color=line.get_color(), alpha=0.15, linewidth=0)
    if all(float(v).is_integer() for v in x):  # rounds, seeds: whole-number ticks
        ax.set_xticks(sorted({int(v) for v in x}))
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.set_title(title)
    ax.grid(alpha=0.3)
    ax.legend()
    save_figure(fig, path)


def voxel_rows(
    rows: list[list[tuple[np.ndarray, np.ndarray]]],
    row_labels: list[str],
    col_labels: list[str],
    path: str | os.PathLike,
    title: str,
) -> None:
    """A grid of voxel shapes; each cell is (occupancy, main-part mask): main part green, the rest red.

    rows : per row, per column, ``(occupancy (R, R, R) bool, main (R, R, R) bool)``
    """
    plt = pyplot()
    n_rows, n_cols = len(rows), len(rows[0])
    height = 1.9 * n_rows + 0.5  # inches: a row per shape and the title's line
    fig = plt.figure(figsize=(1.9 * n_cols, height))
    # margins in inches, not shares of the height: the title sits its own line above the first row, whatever the rows
    fig.subplots_adjust(left=0.06, right=0.99, bottom=0.01, top=1 - 0.42 / height, wspace=0.02, hspace=0.08)
    for r, row in enumerate(rows):
        for c, (occ, main) in enumerate(row):
            ax = fig.add_subplot(n_rows, n_cols, r * n_cols + c + 1, projection="3d")
            R = occ.shape[0]
            for mask, color in ((occ & main, "#2ca02c"), (occ & ~main, "#d62728")):
                pts = np.argwhere(mask)
                if len(pts):
                    ax.scatter(pts[:, 0], pts[:, 1], pts[:, 2], s=2, c=color, depthshade=True, linewidths=0)
            ax.set_xlim(0, R)
            ax.set_ylim(0, R)
            ax.set_zlim(0, R)
            ax.set_axis_off()
            ax.view_init(elev=25, azim=40)
            ax.set_box_aspect(None, zoom=1.3)  # the cube fills its cell (3D axes keep a wide margin by default)
            if r == 0:
                ax.set_title(col_labels[c], fontsize=8, pad=0)
            if c == 0:
                ax.text2D(-0.15, 0.5, row_labels[r], transform=ax.transAxes, rotation=90, va="center", fontsize=8)
    fig.suptitle(title, fontsize=10, y=1 - 0.08 / height, va="top")
    save_figure(fig, path)


def histogram(counts: np.ndarray, edges: np.ndarray, path: str | os.PathLike, xlabel: str, title: str) -> None:
    """Bars of ``counts`` (B,) over bin ``edges`` (B + 1,)."""
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.bar(edges[:-1], counts, width=np.diff(edges), align="edge", edgecolor="white", color="tab:blue")
    ax.set_xlabel(xlabel)
    ax.set_ylabel("shapes")
    ax.set_title(title)
    ax.grid(alpha=0.3, axis="y")
    save_figure(fig, path)


def grasps_on_shapes(
    shapes: list[tuple[np.ndarray, np.ndarray]],
    segments: list[np.ndarray],
    qualities: list[np.ndarray],
    titles: list[str],
    path: str | os.PathLike,
    vmax: float,
    threshold: float,
) -> None:
    """Shapes side by side with their grasps drawn as contact-to-contact segments.

    shapes : per shape ``(vertices (V, 3) m, faces (F, 3))``
    segments : per shape (G, 2, 3) contact pairs, m
    qualities : per shape (G,) robust ε, colored red (0) to green (``vmax``); the colorbar marks ``threshold``
    """
    plt = pyplot()
    from matplotlib.colors import Normalize
    from mpl_toolkits.mplot3d.art3d import Line3DCollection, Poly3DCollection

    norm = Normalize(0.0, vmax)
    cmap = plt.get_cmap("RdYlGn")
    if not shapes:
        fig, ax = plt.subplots(figsize=(4.5, 2))
        ax.text(0.5, 0.5, "no shape with grasps", ha="center", va="center")
        ax.set_axis_off()
        save_figure(fig, path)
        return
    fig = plt.figure(figsize=(4.5 * len(shapes), 4.8))
    for i, ((vertices, faces), seg, q, title) in enumerate(zip(shapes, segments, qualities, titles)):
        ax = fig.add_subplot(1, len(shapes), i + 1, projection="3d")
        ax.add_collection3d(Poly3DCollection(vertices[faces], facecolor=(0.75, 0.75, 0.8, 0.25), edgecolor="none"))
        ax.add_collection3d(Line3DCollection(seg, colors=cmap(norm(q)), linewidths=1.6))
        half = 0.5 * np.ptp(vertices, axis=0).max()
        mid = 0.5 * (vertices.max(axis=0) + vertices.min(axis=0))
        ax.set(
            xlim=(mid[0] - half, mid[0] + half),
            ylim=(mid[1] - half, mid[1] + half),
            zlim=(mid[2] - half, mid[2] + half),
        )
        ax.set_box_aspect((1, 1, 1))
        ax.set_axis_off()
        ax.set_title(title, fontsize=10)
    bar = fig.colorbar(plt.cm.ScalarMappable(norm=norm, cmap=cmap), ax=fig.axes, shrink=0.6, label="robust ε")
    bar.ax.axhline(threshold, color="black", linewidth=1.5)
    save_figure(fig, path)


def crop_grid(
    images: np.ndarray,
    titles: Sequence[str],
    jaw_half_widths: Sequence[float],
    path: str | os.PathLike,
    title: str,
    columns: int = 6,
) -> None:
    """Depth crops (n, s, s) (m) in a grid, each in its own gray scale (near = light), with its
    title and the open jaws drawn as two vertical red ticks ``jaw_half_widths`` pixels left and
    right of the center (the jaw axis is the crop's horizontal)."""
    plt = pyplot()
    n = len(images)
    rows = max(1, int(np.ceil(n / columns)))
    fig, axes = plt.subplots(rows, columns, figsize=(1.9 * columns, 2.1 * rows), squeeze=False)
    for ax in axes.ravel():
        ax.axis("off")
    for ax, image, label, half in zip(axes.ravel(), images, titles, jaw_half_widths):
        size = image.shape[0]
        center = (size - 1) / 2
        ax.imshow(-image, cmap="gray", interpolation="nearest")
        for side in (-1, 1):
            ax.plot([center + side * half] * 2, [center - size / 8, center + size / 8], color="red", linewidth=1.5)
        ax.plot([center], [center], marker="+", color="tab:blue", markersize=6)
        ax.set_title(label, fontsize=7)
    if n == 0:
        axes[0, 0].text(0.5, 0.5, "no datapoints", ha="center", va="center", transform=axes[0, 0].transAxes)
    fig.suptitle(title, fontsize=9)
    save_figure(fig, path)


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


def validation_curves(history, path: str | os.PathLike, title: str) -> None:
    """Validation AP against SGD step, one line per network (``history``: columns network,
    step, val_ap), a dot at each network's best evaluation (the weights it keeps)."""
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(7.2, 4.6))
    for name, rows in history.groupby("network", sort=True):
        style = {"random": "--", "real": ":", "recon": "-."}.get(name.split("/")[0], "-")
        (line,) = ax.plot(rows.step, rows.val_ap, linestyle=style, linewidth=1.2, label=name)
        if rows.val_ap.notna().any():
            best = rows.loc[rows.val_ap.idxmax()]
            ax.plot([best.step], [best.val_ap], "o", color=line.get_color(), markersize=4)
    ax.set_xlabel("SGD step")
    ax.set_ylabel("validation Average Precision")
    ax.set_title(title, fontsize=9)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=6, ncol=2)
    save_figure(fig, path)


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


BARS_PER_ROW = 12  # success_bars wraps its objects into rows of at most this many (about 1,400 px wide)


def success_bars(
    names: Sequence[str],
    arms: dict[str, tuple[np.ndarray, np.ndarray, np.ndarray]],
    path: str | os.PathLike,
    title: str,
) -> None:
    """Grouped bars of success rate per object and arm; ``arms[label] = (rate, low, high)``,
    each (len(names),), drawn with the interval as error bars. The objects wrap into as few rows as
    hold at most :data:`BARS_PER_ROW` each, filled evenly, so many objects make a taller figure,
    not a wider one."""
    plt = pyplot()
    n_rows = max(1, -(-len(names) // BARS_PER_ROW))
    per_row = max(1, -(-len(names) // n_rows))
    fig, axes = plt.subplots(
        n_rows, 1, figsize=(max(6.0, 0.9 * per_row + 2), 3.2 * n_rows + 0.8), squeeze=False, layout="constrained"
    )
    width = 0.8 / max(1, len(arms))
    for row, ax in enumerate(axes[:, 0]):
        shown = slice(row * per_row, (row + 1) * per_row)
        x = np.arange(len(names[shown]))
        for i, (label, (rate, low, high)) in enumerate(arms.items()):
            rate, low, high = (np.asarray(a, dtype=float)[shown] for a in (rate, low, high))
            offset = x + (i - (len(arms) - 1) / 2) * width
            ax.bar(offset, rate, width, yerr=[rate - low, high - rate], capsize=3, label=label)
        ax.set_xticks(x)
        ax.set_xticklabels(names[shown], rotation=30, ha="right")
        ax.set_xlim(-0.5, per_row - 0.5)  # the same bar width in every row
        ax.set_ylim(0, 1.25)
        ax.set_yticks(np.linspace(0, 1, 6))
        ax.set_ylabel("grasp success rate")
    axes[0, 0].set_title(title)
    axes[0, 0].legend(loc="upper center", ncol=min(len(arms), 3), fontsize=8)
    save_figure(fig, path)


def pick_story(
    depth: np.ndarray,
    jaw: np.ndarray | None,
    window: tuple[int, int, int, int],
    frames: Sequence[tuple[str, np.ndarray]],
    path: str | os.PathLike,
    title: str,
) -> None:
    """One trial: the depth image (m) inside ``window`` = (u0, v0, u1, v1) px with the chosen
    grasp's jaw segment ``jaw`` (2, 2) as (u, v) rows drawn, then the RGB pick frames."""
    plt = pyplot()
    panels = 1 + len(frames)
    fig, axes = plt.subplots(1, panels, figsize=(2.9 * panels, 2.9), layout="constrained")
    axes = np.atleast_1d(axes)
    u0, v0, u1, v1 = window
    shown = axes[0].imshow(depth[v0:v1, u0:u1], cmap="viridis", extent=(u0 - 0.5, u1 - 0.5, v1 - 0.5, v0 - 0.5))
    if jaw is not None:
        axes[0].plot(jaw[:, 0], jaw[:, 1], "r-", lw=2)
        axes[0].plot(jaw[:, 0], jaw[:, 1], "ro", ms=4)
    fig.colorbar(shown, ax=axes[0], location="bottom", fraction=0.05, pad=0.02, label="depth (m)")
    axes[0].set_title("depth image + grasp", fontsize=8)
    for ax, (label, frame) in zip(axes[1:], frames):
        ax.imshow(frame)
        ax.set_title(label, fontsize=8)
    for ax in axes:
        ax.set_xticks([])
        ax.set_yticks([])
    fig.suptitle(title, fontsize=9)
    save_figure(fig, path)


def generated_pairs(base: np.ndarray, voxels, decoded: list, path: str | os.PathLike, title: str) -> None:
    """Parent a | child | parent b for each of ``decoded`` (``graspaug.augment.candidates.Decoded``), from
    base set ``base`` (shape ids, indexed by the candidates) and the corpus' ``voxels`` (VoxelSet)."""
    row_of = {s: i for i, s in enumerate(voxels.shape_id)}

    def parent(shape_id: str) -> tuple[np.ndarray, np.ndarray]:
        grid = voxels.occupancy[row_of[shape_id]].astype(bool)
        return grid, grid

    rows, labels = [], []
    resolution = voxels.occupancy.shape[1]
    for d in decoded:
        c = d.candidate
        child = np.unpackbits(d.packed_grid, count=resolution**3).reshape((resolution,) * 3).astype(bool)
        rows.append([parent(base[c.a]), (child, child), parent(base[c.b])])
        labels.append(f"{c.selected_by}, α={c.alpha:g}")
    voxel_rows(rows, labels, ["parent a", "generated", "parent b"], path, title)


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


def label_calibration(by_eps: pd.DataFrame, grasps: pd.DataFrame, path: str | os.PathLike, title: str) -> None:
    """Do executed grasps follow their labels? Left: success rate per robust-ε bin (``by_eps``:
    ``collision_free``, ``eps_mid``, ``rate``, ``lo``, ``hi``), one line for grasps labelled
    collision-free and one for colliding ones. Right: ROC curves of
    the robust ε and of the label against the executed outcome (``grasps``: ``eps``, ``label``,
    ``executed_success``), AUC in the legend."""
    from sklearn.metrics import roc_auc_score, roc_curve

    plt = pyplot()
    fig, (rates, roc) = plt.subplots(1, 2, figsize=(11, 4.5))
    for free, group in by_eps.groupby("collision_free"):
        group = group.sort_values("eps_mid")
        rate = group.rate.to_numpy(float)
        rates.errorbar(
            group.eps_mid * 1000,
            rate,
            yerr=[rate - group.lo.to_numpy(float), group.hi.to_numpy(float) - rate],
            marker="o",
            capsize=3,
            label="labelled collision-free approach" if free else "labelled colliding approach",
        )
    rates.set_xlabel("robust ε (×1000), median of the bin")
    rates.set_ylabel("executed success rate (95% Wilson)")
    rates.set_ylim(0, 1.02)
    y = grasps.executed_success.to_numpy(bool)
    if 0 < y.sum() < len(y):
        for name, score in (("robust ε", grasps.eps), ("label", grasps.label.astype(float))):
            fpr, tpr, _ = roc_curve(y, score)
            roc.plot(fpr, tpr, label=f"{name} (AUC {roc_auc_score(y, score):.3f})")
    else:
        roc.text(0.5, 0.5, "one outcome only: no curve", ha="center", va="center")
    roc.plot([0, 1], [0, 1], color="gray", ls=":", label="chance")
    roc.set_xlabel("false positive rate")
    roc.set_ylabel("true positive rate")
    for ax in (rates, roc):
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle(title)
    save_figure(fig, path)
