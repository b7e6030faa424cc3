"""Stage ``grasp_calibration``: do the robot cell's outcomes follow the grasp labels?

``sim.calibration_grasps`` datapoints of the rendered test split (half labelled positive, spread over the test
shapes) are executed in the ``sim`` stage's cell: each shape is put on the table in its datapoint's stable pose
and the Panda executes that grasp (:mod:`graspaug.experiments.cell.calibration`). Writes
``metrics/grasp_calibration/<figure>.json`` (``mean``, ``lo``, ``hi``, bootstrap over shapes: success per label;
ROC AUC of the robust ε over all grasps, over collision-free ones, of ε on collision-free grasps and 0 on colliding
ones, and of the label) and ``reports/grasp_calibration/`` (``summary.json`` with the outcome counts,
``grasps.csv`` one row per executed grasp, ``by_eps.csv`` and ``calibration.png``: success per ε bin and the ROC
curves).
"""

from __future__ import annotations

import logging
import time

from graspaug.experiments.cell.calibration import (
    calibration_headline,
    choose_grasps,
    draw_label_calibration,
    run_calibration,
    shape_jobs,
    success_by_eps,
    summarize,
    summary_line,
)
from graspaug.io.atomic import atomic_path
from graspaug.io.tables import read_table, write_csv, write_json, write_json_files
from graspaug.pipeline.params.base import params_model
from graspaug.pipeline.params.grasps import GraspsParams
from graspaug.pipeline.params.sim import SimParams
from graspaug.pipeline.paths import (
    CALIBRATION_METRICS,
    CALIBRATION_REPORT_DIR,
    SHAPES_DIR,
    SHAPES_TABLE,
    gqcnn_dir,
    grasps_table,
)
from graspaug.pipeline.stages import StageError
from graspaug.training.gqcnn_data import with_split

log = logging.getLogger(__name__)

Params = params_model("The params the `grasp_calibration` stage reads.", grasps=GraspsParams, sim=SimParams)


def run(params: Params) -> None:
    start = time.perf_counter()
    cfg = params.sim
    try:
        chosen = choose_grasps(
            with_split(read_table(gqcnn_dir("original") / "index.parquet"), read_table(SHAPES_TABLE)),
            cfg.calibration_grasps,
            params.seed,
        )
    except ValueError as exc:
        raise StageError(f"grasp_calibration: {exc}") from None
    jobs = shape_jobs(chosen, read_table(grasps_table("original")), SHAPES_DIR, cfg, params.seed, params.workers)
    log.info(
        "grasp_calibration: %d labelled grasps (%d positive) on %d test shapes",
        len(chosen),
        chosen.label.sum(),
        len(jobs),
    )
    table = run_calibration(jobs, cfg, params.workers, params.grasps.gripper)
    summary = summarize(table, cfg.n_bootstrap, params.seed)
    summary["seconds"] = round(time.perf_counter() - start, 1)
    by_eps = success_by_eps(table)
    with atomic_path(CALIBRATION_REPORT_DIR, directory=True) as out:
        write_csv(table, out / "grasps.csv")
        write_csv(by_eps, out / "by_eps.csv")
        write_json(summary, out / "summary.json")
        draw_label_calibration(by_eps, table, out / "calibration.png")
    write_json_files(calibration_headline(summary), CALIBRATION_METRICS)
    log.info("grasp_calibration: %s; %.0f s", summary_line(summary), summary["seconds"])


if __name__ == "__main__":
    from graspaug.pipeline.entry import stage_main

    stage_main(__spec__.name)
