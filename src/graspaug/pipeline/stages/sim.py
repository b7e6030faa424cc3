"""Stage ``sim``: simulated Panda pick-and-place trials with the GQ-CNN before and after augmentation.

Arms (:func:`~graspaug.experiments.cell.trials.arms`): ``before``, ``after`` (the ratio chosen on validation AP),
``real``, ``more_real`` (the positive control), each per training seed, ``antipodal`` (the floor) and ``oracle`` (the
ceiling), on the same ``sim.attempts`` drops of every object, each judged feasible from its geometry first; each
arm's networks also rank the grasps ``grasp_calibration`` executed here. Writes ``metrics/sim/<contrast>.json``
(``mean``, ``lo``, ``hi``; ``ranking_<contrast>``) and ``reports/sim/`` (``summary.json``, ``report.md`` opening with
the oracle's verdict on the cell, ``trials.csv``, ``success.{csv,png}``, ``objects.csv``, ``calibration.csv``,
``timing.json``, ``trials/<arm>-<object>.png``); docs/stages.md (``sim``) says what each holds."""

from __future__ import annotations

import json
import logging
import time

from graspaug.experiments.cell.figures import write_trials_report
from graspaug.experiments.cell.numbers import (
    calibration,
    cell_ranking,
    planning_timing,
    sim_headline,
    summarize,
    trial_setup,
)
from graspaug.experiments.cell.trials import (
    after_ratio,
    arms,
    object_feasibility,
    object_jobs,
    run_trials,
    trial_objects,
    trials_plan,
    trials_table,
)
from graspaug.experiments.cell.words import outcome_words
from graspaug.io.atomic import atomic_path
from graspaug.io.tables import read_table, write_json, write_json_files
from graspaug.pipeline import paths
from graspaug.pipeline.params.base import params_model
from graspaug.pipeline.params.generate import GenerateParams
from graspaug.pipeline.params.gqcnn import GQCNNParams
from graspaug.pipeline.params.grasps import GraspsParams
from graspaug.pipeline.params.ingest import IngestParams
from graspaug.pipeline.params.render import RenderParams
from graspaug.pipeline.params.sim import SimParams
from graspaug.pipeline.provenance import report_header
from graspaug.pipeline.stages import StageError

log = logging.getLogger(__name__)
NO_AP = "sim: %s has no AP for base size %d; comparing ratio 0 with the largest ratio %g"

Params = params_model(
    "The params the `sim` stage reads.",
    ingest=IngestParams,
    grasps=GraspsParams,
    generate=GenerateParams,
    render=RenderParams,
    gqcnn=GQCNNParams,
    sim=SimParams,
)


def run(params: Params) -> None:
    start = time.perf_counter()
    cfg, model_seeds = params.sim, list(params.gqcnn.seeds)
    executed = paths.CALIBRATION_REPORT_DIR / "grasps.csv"  # the calibration's grasps, which every network ranks
    for path, stage in ((paths.AP_REPORT, "report"), (executed, "grasp_calibration")):
        if not path.exists():
            raise StageError(f"{path} is missing: run `dvc repro {stage}` first")
    best, from_report = after_ratio(json.loads(paths.AP_REPORT.read_text()), cfg.base_size, params.generate.ratios)
    if not from_report:
        log.warning(NO_AP, paths.AP_REPORT, cfg.base_size, best)
    seed_dirs = {seed: paths.gqcnn_seed_dir(seed) for seed in model_seeds}
    chosen = arms(best, cfg.base_size, seed_dirs, params.generate.base_sizes)
    # an empty or unreadable sim.objects_path: a DataError, which the CLI prints in one line
    shapes = read_table(paths.SHAPES_TABLE)
    objects, skipped = trial_objects(cfg, shapes, paths.SHAPES_DIR, params.ingest, params.seed, params.workers)
    feasible = object_feasibility(objects, params.grasps.gripper.max_width)  # from geometry, before any pick
    jobs = object_jobs(objects, chosen, seed_dirs, cfg.attempts, params.seed, cfg.n_pictures)
    log.info("sim: %s", trials_plan(objects, chosen, cfg.attempts, len(model_seeds), skipped, feasible))
    rows = run_trials(jobs, cfg, params.render.crop, params.workers, params.grasps.gripper, params.grasps)
    trials = trials_table(rows, chosen, feasible)
    setup = trial_setup(cfg, objects, skipped, model_seeds, after_from_report=from_report, data_seed=params.data_seed)
    metrics = summarize(trials, objects, chosen, setup, cfg.n_bootstrap, params.seed)
    scores = read_table(paths.SCORES).set_index("shape_id")  # no grasp sampled: n/a, not 0
    calibration_table, metrics["calibration"] = calibration(trials, scores.graspness[scores.n_grasps > 0])
    metrics["ranking"] = cell_ranking(read_table(executed), seed_dirs, chosen, cfg.n_bootstrap, params.seed)
    timing = planning_timing(trials, list(chosen))

    header = report_header(params.file_text, shapes)  # the profile and corpus that made the report
    with atomic_path(paths.SIM_REPORT_DIR, directory=True) as out:
        write_trials_report(
            out, rows, trials, objects, calibration_table, metrics, chosen, model_seeds, paths.SCORES.as_posix(), header
        )
        timing["stage_seconds"] = round(time.perf_counter() - start, 1)
        write_json(timing, out / "timing.json")
        write_json(metrics, out / "summary.json")
    write_json_files(sim_headline(metrics), paths.SIM_METRICS)
    log.info("sim: %s; %.0f s", outcome_words(metrics, timing), time.perf_counter() - start)


if __name__ == "__main__":
    from graspaug.pipeline.entry import stage_main

    stage_main(__spec__.name)
