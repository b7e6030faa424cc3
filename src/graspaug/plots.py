"""Figures as PNG files (matplotlib, Agg backend): what the figures share, and the stages' own pictures.

The saving (:func:`pyplot`, :func:`save_figure`, :data:`DPI`), the primitives several figures call (lines with bands,
a scatter map, voxel rows) and the pictures of the pipeline's stages (score histograms and grasps, depth crops,
validation curves, generated pairs). An experiment's figure is drawn in its own ``figures`` module
(``experiments/<name>/figures.py``), beside its data and caption."""

from __future__ import annotations

import os
from collections.abc import Sequence

import numpy as np

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
