"""Figures as PNG files (matplotlib, Agg backend): what the stages show a person."""
from __future__ import annotations

import os
from collections.abc import Sequence

import numpy as np

from graspaug.io.atomic import atomic_path


def _pyplot():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _save(fig, path: str | os.PathLike) -> None:
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=110, bbox_inches="tight", format="png")
    _pyplot().close(fig)


def scatter_2d(xy: np.ndarray, groups: Sequence[str], path: str | os.PathLike, title: str) -> None:
    """(N, 2) points colored by group label (e.g. the t-SNE map by split)."""
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(6, 6))
    groups = np.asarray(groups)
    for name in sorted(set(groups)):
        sel = groups == name
        ax.scatter(xy[sel, 0], xy[sel, 1], s=8, alpha=0.7, label=f"{name} ({sel.sum()})")
    ax.set_title(title)
    ax.set_xticks([])
    ax.set_yticks([])
    ax.legend()
    _save(fig, path)


def lines(x: Sequence[float], series: dict[str, Sequence[float]], path: str | os.PathLike, xlabel: str, ylabel: str, title: str) -> None:
    """One line per series over shared x values."""
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(6, 4))
    for name, y in series.items():
        ax.plot(x, y, marker="o", label=name)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.set_title(title)
    ax.grid(alpha=0.3)
    ax.legend()
    _save(fig, path)


def voxel_rows(rows: list[list[tuple[np.ndarray, np.ndarray]]], row_labels: list[str], col_labels: list[str], path: str | os.PathLike, title: str) -> None:
    """A grid of voxel shapes; each cell is (occupancy, main-part mask): main part green, the rest red.

    rows : per row, per column, ``(occupancy (R, R, R) bool, main (R, R, R) bool)``
    """
    plt = _pyplot()
    n_rows, n_cols = len(rows), len(rows[0])
    fig = plt.figure(figsize=(1.9 * n_cols, 1.9 * n_rows))
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
            if r == 0:
                ax.set_title(col_labels[c], fontsize=8)
            if c == 0:
                ax.text2D(-0.15, 0.5, row_labels[r], transform=ax.transAxes, rotation=90, va="center", fontsize=8)
    fig.suptitle(title, fontsize=10)
    _save(fig, path)
