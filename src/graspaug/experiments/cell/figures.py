"""The cell's figures, each with its data, drawing and caption: the success bars (:func:`success_bar_data`,
:func:`success_bars`), the picture of each recorded attempt (:func:`trial_picture`, :func:`pick_story`), and the report
folder's files (:func:`write_trials_report`, which titles the bars). The grasp calibration's figure is
:mod:`graspaug.experiments.cell.calibration`'s."""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path

import numpy as np
import pandas as pd

from graspaug.experiments.cell.numbers import objects_table, success_table
from graspaug.experiments.cell.picks import ANTIPODAL, ORACLE
from graspaug.experiments.cell.words import report_text
from graspaug.io.tables import write_csv
from graspaug.plots import pyplot, save_figure


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


def trial_picture(row: dict, ratio: float | None) -> dict:
    """What :func:`pick_story` draws of a recorded attempt (a :func:`run_object`
    row): ``depth`` (H, W) m, missing pixels NaN; ``jaw`` (2, 2) the jaw endpoints (u, v) px or
    None; ``window`` (u0, v0, u1, v1) px around the grasp; ``frames``; ``title``. ``ratio``: the
    arm's (None: no network)."""
    from graspaug.planning.grasps import jaw_endpoints

    depth = np.where(row["_depth"] > 0, row["_depth"], np.nan)  # missing pixels (0) left blank
    h, w = depth.shape
    jaw = None
    if row["u"] is not None:
        jaw = jaw_endpoints(np.array([[row["u"], row["v"]]]), np.array([row["angle"]]), np.array([row["width_px"]]))[0]
        cu, cv = int(round(row["u"])), int(round(row["v"]))
    else:
        cu, cv = w // 2, h // 2
    r = min(80, h // 2, w // 2)
    u0, v0 = int(np.clip(cu - r, 0, w - 2 * r)), int(np.clip(cv - r, 0, h - 2 * r))
    q = row["quality"]
    quality = "no grasp found" if q is None else ("random" if np.isnan(q) else f"Q = {q:.3f}")
    network = "random antipodal grasp, no network" if ratio is None else f"ratio {ratio:g}, training seed {row['seed']}"
    title = f"{row['object']}, arm {row['arm']} ({network}), attempt 0: {quality} → {row['outcome']}"
    return {
        "depth": depth,
        "jaw": jaw,
        "window": (u0, v0, u0 + 2 * r, v0 + 2 * r),
        "frames": row["_frames"],
        "title": title,
    }


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


#: The success bars' labels of the arms without a network.
BAR_LABELS = {ANTIPODAL: "random antipodal grasp (no network)", ORACLE: "oracle: best grasp on the true mesh"}


def success_bar_data(metrics: dict, chosen: dict) -> tuple[list[str], dict[str, tuple[np.ndarray, ...]]]:
    """What :func:`success_bars` draws: the objects and ``all``, and per arm's label
    (rate, Wilson low, Wilson high), each (objects + 1,)."""
    names = [*metrics["per_object"], "all"]
    bars = {}
    for arm, (pool, ratio, base_size) in chosen.items():
        label = BAR_LABELS.get(arm) or f"{arm} ({pool}, B = {base_size}, ratio {ratio:g})"
        stats = [metrics["per_object"][n][arm] for n in names[:-1]] + [metrics["arms"][arm]]
        bars[label] = tuple(np.array([s[key] for s in stats]) for key in ("success_rate", "wilson_low", "wilson_high"))
    return names, bars


def write_trials_report(
    out: Path,
    rows: list[dict],
    trials: pd.DataFrame,
    objects: Sequence,
    calibration_table: pd.DataFrame,
    metrics: dict,
    chosen: dict,
    model_seeds: list[int],
    scores_file: str,
    header: str = "",
) -> None:
    """Write into the folder ``out``: ``trials.csv`` (``trials`` without planning times),
    ``objects.csv``, ``calibration.csv``, ``success.csv`` and ``success.png`` (rate per object and
    arm, 95 % Wilson intervals), ``trials/<arm>-<object>.png`` for every recorded attempt of
    ``rows`` (:func:`graspaug.experiments.cell.trials.run_object`'s) and ``report.md``. ``objects``: the
    :class:`~graspaug.experiments.cell.trials.PreparedObject` of the trials; ``metrics``:
    :func:`~graspaug.experiments.cell.numbers.summarize`'s with ``calibration``; ``chosen``: arm →
    (pool, ratio); ``scores_file``: the scores table's path as the report names it; ``header``: the lines report.md
    opens with (the profile and corpus that made it)."""
    base_size = metrics["setup"]["base_size"]
    write_csv(trials.drop(columns=["planning_time"]), out / "trials.csv")
    write_csv(objects_table(objects), out / "objects.csv")
    write_csv(calibration_table, out / "calibration.csv")
    write_csv(success_table(metrics, list(chosen)), out / "success.csv")
    success_bars(
        *success_bar_data(metrics, chosen),
        out / "success.png",
        f"Pick success per object, B = {base_size}, training seeds {model_seeds} (95% Wilson intervals)",
    )
    (out / "trials").mkdir()
    for row in rows:
        if row["_depth"] is not None:
            path = out / "trials" / f"{row['arm']}-{row['object']}.png"
            pick_story(**trial_picture(row, chosen[row["arm"]][1]), path=path)
    (out / "report.md").write_text(header + report_text(metrics, trials, calibration_table, scores_file))
