"""The cell's figures: the success bars, the picture of each recorded attempt, and the report folder's files."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np
import pandas as pd

from graspaug.experiments.cell.numbers import objects_table, success_table
from graspaug.experiments.cell.words import report_text
from graspaug.io.tables import write_csv


def trial_picture(row: dict, ratio: float | None) -> dict:
    """What :func:`graspaug.plots.pick_story` draws of a recorded attempt (a :func:`run_object`
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


def success_bar_data(metrics: dict, chosen: dict) -> tuple[list[str], dict[str, tuple[np.ndarray, ...]]]:
    """What :func:`graspaug.plots.success_bars` draws: the objects and ``all``, and per arm's label
    (rate, Wilson low, Wilson high), each (objects + 1,)."""
    names = [*metrics["per_object"], "all"]
    bars = {}
    for arm, (pool, ratio, base_size) in chosen.items():
        label = (
            "random antipodal grasp (no network)"
            if pool is None
            else f"{arm} ({pool}, B = {base_size}, ratio {ratio:g})"
        )
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
    from graspaug.plots import pick_story, success_bars

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
