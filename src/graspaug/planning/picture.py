"""The picture of a plan (``grasp.png`` of ``graspaug plan``): the object's region enlarged, each grasp drawn as
the gripper's fingers and closing line, numbered, with the crop the network scored."""

from __future__ import annotations

import os
from collections.abc import Sequence

import numpy as np

from graspaug.plots import pyplot, save_figure

#: Colours of the planned grasps by rank (#1 first), repeated beyond ten.
GRASP_COLORS = (
    "#e6194b",
    "#1f78ff",
    "#2ca02c",
    "#ff8c00",
    "#b04cd6",
    "#00bcd4",
    "#e377c2",
    "#8c564b",
    "#bcbd22",
    "#1a1a80",
)


def _table_residual(depth: np.ndarray) -> np.ndarray:
    """``depth`` (H, W) m minus the table plane fitted to it (negative: nearer than the table).
    The plane is refitted three times to the pixels that do not stand 5 mm or more above it."""
    h, w = depth.shape
    step = max(1, int(np.sqrt(h * w / 20000)))
    v, u = np.mgrid[0:h:step, 0:w:step]
    z = depth[::step, ::step]
    basis = np.stack([u.ravel(), v.ravel(), np.ones(u.size)], axis=1).astype(float)
    keep = np.isfinite(z.ravel())
    coef = np.array([0.0, 0.0, float(np.nanmedian(depth))])
    for _ in range(3):
        if keep.sum() < 3:
            break
        coef = np.linalg.lstsq(basis[keep], z.ravel()[keep], rcond=None)[0]
        keep = np.isfinite(z.ravel()) & (z.ravel() - basis @ coef > -0.005)
    vv, uu = np.mgrid[0:h, 0:w]
    return depth - (coef[0] * uu + coef[1] * vv + coef[2])


def _grasp_region(
    depth: np.ndarray, jaws: Sequence[np.ndarray], reach: Sequence[float]
) -> tuple[tuple[int, int, int, int], np.ndarray]:
    """The square window (u0, v0, u1, v1) px, end exclusive, that shows the object and the grasps,
    and the object's pixels (H, W) bool: the blobs of pixels 3 mm or more nearer than the table
    that a grasp touches (without grasps the largest blob). The window holds them and the grasps'
    jaws widened by ``reach`` px, with a margin."""
    from scipy import ndimage

    h, w = depth.shape
    blobs, count = ndimage.label(_table_residual(depth) < -0.003)
    points = [np.asarray(j, dtype=float).reshape(-1, 2) for j in jaws]
    if points:
        touched = np.zeros(count + 1, dtype=bool)
        for jaw, r in zip(points, reach):
            lo = np.clip(np.floor(jaw.min(axis=0) - r), 0, [w - 1, h - 1]).astype(int)
            hi = np.clip(np.ceil(jaw.max(axis=0) + r) + 1, 1, [w, h]).astype(int)
            touched[np.unique(blobs[lo[1] : hi[1], lo[0] : hi[0]])] = True
        touched[0] = False
        mask = touched[blobs]
    elif count:
        sizes = np.bincount(blobs.ravel())[1:]
        mask = blobs == 1 + int(np.argmax(sizes))
    else:
        return (0, 0, w, h), np.zeros((h, w), dtype=bool)
    v, u = np.nonzero(mask)
    corners = [np.stack([u, v], axis=1).astype(float)] if len(u) else []
    corners += [np.concatenate([p - r, p + r]) for p, r in zip(points, reach)]
    if not corners:
        return (0, 0, w, h), mask
    stacked = np.concatenate(corners)
    low, high = stacked.min(axis=0), stacked.max(axis=0) + 1
    side = max(float(np.max(high - low)) * 1.35, 48.0)
    side = int(min(np.ceil(side), w, h))
    center = (low + high) / 2
    u0 = int(np.clip(round(center[0] - side / 2), 0, w - side))
    v0 = int(np.clip(round(center[1] - side / 2), 0, h - side))
    return (u0, v0, u0 + side, v0 + side), mask


def _label_spots(shapes: Sequence[np.ndarray], clearance: float, window: tuple[int, int, int, int]) -> np.ndarray:
    """A place (u, v) px for each grasp's number, best grasp first: ``clearance`` px away from a
    point of its own drawing (``shapes``: per grasp (P, 2) points along its fingers and closing
    line), as far as possible (up to ``clearance``) from every drawn point and from the numbers
    placed before, inside ``window`` (u0, v0, u1, v1), and then nearest its own center."""
    u0, v0, u1, v1 = window
    turns = np.linspace(0, 2 * np.pi, 16, endpoint=False)
    directions = np.stack([np.cos(turns), np.sin(turns)], axis=1)
    drawn = np.concatenate(shapes) if len(shapes) else np.zeros((0, 2))
    placed: list[np.ndarray] = []
    pad = 0.04 * (u1 - u0)
    for own in shapes:
        spots = (own[:, None] + clearance * directions[None]).reshape(-1, 2)
        score = np.linalg.norm(spots[:, None] - drawn[None], axis=2).min(axis=1)
        if placed:
            labels = np.linalg.norm(spots[:, None] - np.array(placed)[None], axis=2).min(axis=1)
            score = np.minimum(score, labels - 0.5 * clearance)
        score = np.minimum(score, clearance)
        inside = (
            (spots[:, 0] > u0 + pad) & (spots[:, 0] < u1 - pad) & (spots[:, 1] > v0 + pad) & (spots[:, 1] < v1 - pad)
        )
        score = np.where(inside, score, score - 1e6)
        nearness = np.linalg.norm(spots - own.mean(axis=0), axis=1)
        placed.append(spots[int(np.argmax(score - 0.01 * nearness))])
    return np.array(placed).reshape(-1, 2)


def planned_grasps(
    depth: np.ndarray,
    jaws: Sequence[np.ndarray],
    labels: Sequence[str],
    path: str | os.PathLike,
    title: str,
    finger_px: Sequence[float] | None = None,
    crops: np.ndarray | None = None,
    crop_openings: Sequence[float] | None = None,
    px_per_cm: float | None = None,
    rejected: Sequence[bool] | None = None,
) -> None:
    """The planned grasps on the depth image (H, W) m, readable at a glance.

    The main panel shows the object's region enlarged (:func:`_grasp_region`: the pixels nearer
    than the fitted table plane that the grasps touch, and the grasps) in a grey scale fitted to
    the object's depths (their 2nd-98th percentile, the region's without an object; near =
    light, the table dark); the full frame is a small inset with the region outlined. Each
    ``jaws`` entry (2, 2) holds a grasp's two jaw positions (u, v) px, best first; it is drawn
    as the gripper's two fingers (bars ``finger_px`` px long across the jaw axis, default half the
    opening) joined by the closing line, in its rank's colour (:data:`GRASP_COLORS`), numbered
    beside the grasp and listed with its ``labels`` entry in the legend. ``crops`` (n, s, s) m
    with ``crop_openings`` (n,) px, when given, are the crops the network saw (jaw axis
    horizontal), drawn as small panels; ``px_per_cm`` adds a 1 cm bar. A grasp whose ``rejected``
    entry is True (its P(success) below the quality floor) is drawn faded with a dashed closing line
    and a cross at its center, and its legend entry dashed.
    """
    plt = pyplot()
    from matplotlib import patheffects
    from matplotlib.lines import Line2D
    from matplotlib.patches import Rectangle
    from mpl_toolkits.axes_grid1 import make_axes_locatable

    depth = np.asarray(depth, dtype=float)
    h, w = depth.shape
    jaws = [np.asarray(j, dtype=float).reshape(2, 2) for j in jaws]
    n = len(jaws)
    openings = np.array([np.linalg.norm(j[1] - j[0]) for j in jaws])
    fingers = np.asarray(finger_px, dtype=float) if finger_px is not None else np.maximum(0.5 * openings, 4.0)
    colors = [GRASP_COLORS[i % len(GRASP_COLORS)] for i in range(n)]
    refused = [bool(r) for r in rejected] if rejected is not None else [False] * n
    (u0, v0, u1, v1), mask = _grasp_region(depth, jaws, [0.5 * f + 2 for f in fingers])
    region = depth[v0:v1, u0:u1]
    fitted = depth[mask] if mask.sum() >= 10 else region
    low, high = np.percentile(fitted, [2, 98])
    if high - low < 1e-3:
        low, high = low - 0.0005, high + 0.0005
    white = [patheffects.withStroke(linewidth=4.5, foreground="white")]
    halo = [patheffects.withStroke(linewidth=3.0, foreground="white")]
    dark = [patheffects.withStroke(linewidth=3.0, foreground="black")]

    has_crops = crops is not None and len(crops) > 0
    fig = plt.figure(figsize=(12, 7.2))
    outer = fig.add_gridspec(1, 2, width_ratios=[2.7, 1.15], wspace=0.22)
    ax = fig.add_subplot(outer[0])
    side = outer[1].subgridspec(3, 1, height_ratios=[1.0, 0.3 + 0.09 * max(n, 3), 1.15], hspace=0.25)
    fig.subplots_adjust(left=0.06, right=0.98, top=0.9, bottom=0.08)

    shown = ax.imshow(
        region,
        cmap="gray_r",
        vmin=low,
        vmax=high,
        extent=(u0 - 0.5, u1 - 0.5, v1 - 0.5, v0 - 0.5),
        interpolation="nearest",
    )
    bar_ax = make_axes_locatable(ax).append_axes("right", size="3.5%", pad=0.12)
    fig.colorbar(shown, cax=bar_ax, extend="both", label="depth (m); near = light")
    own = []
    for rank in reversed(range(n)):
        jaw, color = jaws[rank], colors[rank]
        axis = (jaw[1] - jaw[0]) / max(openings[rank], 1e-9)
        across = np.array([-axis[1], axis[0]]) * 0.5 * fingers[rank]
        z = 3 + n - rank
        style, alpha = ("--", 0.55) if refused[rank] else ("-", 1.0)
        ax.plot(*jaw.T, style, color=color, lw=2.0 if rank else 2.6, alpha=alpha, path_effects=halo, zorder=z)
        points = [np.linspace(jaw[0], jaw[1], 9)]
        for p in jaw:
            finger = np.stack([p - across, p + across])
            width = 5.0 if rank else 6.0
            ax.plot(*finger.T, "-", color=color, lw=width, alpha=alpha, solid_capstyle="butt", path_effects=white)
            ax.lines[-1].set_zorder(z)
            points.append(np.linspace(p - across, p + across, 5))
        if refused[rank]:
            center = jaw.mean(axis=0)
            ax.plot(*center, "x", color=color, ms=14, mew=3.5, path_effects=white, zorder=z + 0.5)
        own.insert(0, np.concatenate(points))
    if n:
        size = u1 - u0
        spots = _label_spots(own, 0.06 * size, (u0, v0, u1, v1))
        for rank in range(n):
            target = own[rank][np.argmin(np.linalg.norm(own[rank] - spots[rank], axis=1))]
            ax.annotate(
                str(rank + 1),
                target,
                xytext=spots[rank],
                color="white",
                fontsize=11,
                fontweight="bold",
                ha="center",
                va="center",
                bbox=dict(boxstyle="circle,pad=0.25", fc=colors[rank], ec="white", lw=1.2),
                arrowprops=dict(arrowstyle="-", color=colors[rank], lw=1.2, shrinkA=0, shrinkB=0),
                zorder=10 + n - rank,
            )
    if px_per_cm:
        x0, y0 = u0 + 0.05 * (u1 - u0), v1 - 0.06 * (v1 - v0)
        ax.plot([x0, x0 + px_per_cm], [y0, y0], color="white", lw=3, solid_capstyle="butt", path_effects=dark)
        ax.text(
            x0 + px_per_cm / 2,
            y0 - 0.02 * (v1 - v0),
            "1 cm",
            color="white",
            ha="center",
            va="bottom",
            fontsize=10,
            path_effects=dark,
        )
    ax.set_xlim(u0 - 0.5, u1 - 0.5)
    ax.set_ylim(v1 - 0.5, v0 - 0.5)
    ax.set_xlabel("u (px)")
    ax.set_ylabel("v (px)")
    whole = (u0, v0, u1, v1) == (0, 0, w, h)
    ax.set_title(
        "the whole image" if whole else f"the object, enlarged (u {u0}-{u1 - 1}, v {v0}-{v1 - 1} px)", fontsize=10
    )

    inset = fig.add_subplot(side[0])
    full_low, full_high = np.percentile(depth, [1, 99])
    inset.imshow(depth, cmap="gray_r", vmin=min(full_low, low), vmax=max(full_high, high), interpolation="nearest")
    inset.add_patch(Rectangle((u0 - 0.5, v0 - 0.5), u1 - u0, v1 - v0, fill=False, ec=GRASP_COLORS[0], lw=1.5))
    inset.set_xticks([])
    inset.set_yticks([])
    inset.set_title(f"full frame, {w}×{h} px", fontsize=9)

    legend = fig.add_subplot(side[1])
    legend.axis("off")
    if n:
        handles = [
            Line2D([], [], color=c, ls="--" if r else "-", marker="x" if r else "o", lw=3, markersize=10, mew=2.5)
            for c, r in zip(colors, refused, strict=True)
        ]
        legend.legend(handles, list(labels), loc="center", fontsize=10, frameon=False, title="grasps, best first")
    else:
        legend.text(0.5, 0.5, "no grasp found", ha="center", va="center", fontsize=11)

    panels = fig.add_subplot(side[2])
    panels.axis("off")
    if has_crops:
        count = len(crops)
        columns = min(count, 4 if count <= 8 else 5)
        rows = int(np.ceil(count / columns))
        grid = side[2].subgridspec(rows, columns, hspace=0.3, wspace=0.1)
        shut = [None] * count if crop_openings is None else list(crop_openings)
        for i, (crop, opening) in enumerate(zip(crops, shut)):
            cax = fig.add_subplot(grid[i // columns, i % columns])
            c_low, c_high = np.percentile(crop, [2, 98])
            cax.imshow(crop, cmap="gray_r", vmin=c_low, vmax=max(c_high, c_low + 1e-4), interpolation="nearest")
            s = crop.shape[0]
            mid = (s - 1) / 2
            if opening is not None:
                cax.plot([mid - opening / 2, mid + opening / 2], [mid, mid], color=colors[i], lw=1.2, path_effects=halo)
                for sign in (-1, 1):
                    x = mid + sign * opening / 2
                    cax.plot([x, x], [mid - s / 8, mid + s / 8], color=colors[i], lw=3, path_effects=halo)
            cax.set_xticks([])
            cax.set_yticks([])
            if i == 0:
                cax.set_title("what the network saw (jaw axis horizontal)", fontsize=9, loc="left")
            for spine in cax.spines.values():
                spine.set_edgecolor(colors[i])
                spine.set_linewidth(2.5)
            cax.text(
                0.04,
                0.96,
                f"{i + 1}",
                transform=cax.transAxes,
                color="white",
                fontsize=9,
                fontweight="bold",
                ha="left",
                va="top",
                bbox=dict(boxstyle="circle,pad=0.2", fc=colors[i], ec="white", lw=0.8),
            )
    fig.suptitle(title, fontsize=11)
    save_figure(fig, path)
