"""The files of the simulated trials' report folder (:mod:`graspaug.experiments.sim` runs the trials,
:mod:`graspaug.experiments.sim_report` makes their numbers and text): the tables, the success bars,
a picture per recorded attempt and ``report.md``."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import pandas as pd

from graspaug.experiments.sim import trial_picture
from graspaug.experiments.sim_report import objects_table, report_text, success_bar_data, success_table
from graspaug.io.tables import write_csv


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
) -> None:
    """Write into the folder ``out``: ``trials.csv`` (``trials`` without planning times),
    ``objects.csv``, ``calibration.csv``, ``success.csv`` and ``success.png`` (rate per object and
    arm, 95 % Wilson intervals), ``trials/<arm>-<object>.png`` for every recorded attempt of
    ``rows`` (:func:`graspaug.experiments.sim.run_object`'s) and ``report.md``. ``objects``: the
    :class:`~graspaug.experiments.sim.PreparedObject` of the trials; ``metrics``:
    :func:`~graspaug.experiments.sim_report.summarize`'s with ``calibration``; ``chosen``: arm →
    (pool, ratio); ``scores_file``: the scores table's path as the report names it."""
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
    (out / "report.md").write_text(report_text(metrics, trials, calibration_table, scores_file))
