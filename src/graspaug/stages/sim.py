"""Stage ``sim``: simulated Panda pick-and-place trials with the GQ-CNN before and after augmentation.

Arms (:mod:`graspaug.experiments.sim`): ``before`` (B = ``sim.base_size``, ratio 0), ``after`` (the ratio chosen on
validation AP, ``reports/gqcnn/ap.json``), ``real`` (the ``real`` pool there), ``more_real`` (the next larger B at
ratio 0: the positive control), each per training seed, and ``antipodal`` (no network). Every object (the everyday
objects of ``sim.objects``, ``sim.n_test_objects`` held-out test shapes, the meshes of ``sim.objects_path``), with
mass and friction drawn per object, is dropped ``sim.attempts`` times from seeded poses, the same for every arm;
the planner sees the D435-like noisy depth image and the Panda tries to put the object in the bin.

Writes ``metrics/sim/<contrast>.json`` (``mean``, ``lo``, ``hi``: the paired difference, bootstrap over objects) and
``reports/sim/`` (``summary.json``: per-arm rates with 95 % Wilson intervals, the contrasts in full, per training
seed and per object, the calibration; ``report.md``, ``trials.csv`` one row per attempt, ``success.{csv,png}``
per object, ``objects.csv``, ``calibration.csv``, ``timing.json``, ``trials/<arm>-<object>.png``).
"""

from __future__ import annotations

import json
import logging
import time

from graspaug.experiments.sim import (
    after_ratio,
    arms,
    object_jobs,
    run_trials,
    trial_objects,
    trials_plan,
    trials_table,
)
from graspaug.experiments.sim_outputs import write_trials_report
from graspaug.experiments.sim_report import (
    calibration,
    outcome_words,
    planning_timing,
    sim_headline,
    summarize,
    trial_setup,
)
from graspaug.io.atomic import atomic_path
from graspaug.io.tables import read_table, write_json, write_json_files
from graspaug.params.base import params_model
from graspaug.params.generate import GenerateParams
from graspaug.params.gqcnn import GQCNNParams
from graspaug.params.grasps import GraspsParams
from graspaug.params.ingest import IngestParams
from graspaug.params.render import RenderParams
from graspaug.params.sim import SimParams
from graspaug.paths import AP_REPORT, SCORES, SHAPES_DIR, SHAPES_TABLE, SIM_METRICS, SIM_REPORT_DIR, gqcnn_seed_dir
from graspaug.stages import StageError

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
    if not AP_REPORT.exists():
        raise StageError(f"{AP_REPORT} is missing: run `dvc repro report` first")
    best, from_report = after_ratio(json.loads(AP_REPORT.read_text()), cfg.base_size, params.generate.ratios)
    if not from_report:
        log.warning(NO_AP, AP_REPORT, cfg.base_size, best)
    seed_dirs = {seed: gqcnn_seed_dir(seed) for seed in model_seeds}
    chosen = arms(best, cfg.base_size, seed_dirs, params.generate.base_sizes)
    # an empty or unreadable sim.objects_path: a DataError, which the CLI prints in one line
    objects, skipped = trial_objects(
        cfg, read_table(SHAPES_TABLE), SHAPES_DIR, params.ingest, params.seed, params.workers
    )
    jobs = object_jobs(objects, chosen, seed_dirs, cfg.attempts, params.seed, cfg.n_pictures)
    log.info("sim: %s", trials_plan(objects, chosen, cfg.attempts, len(model_seeds), skipped))
    rows = run_trials(jobs, cfg, params.render.crop, params.workers)
    trials = trials_table(rows, chosen)

    setup = trial_setup(cfg, objects, skipped, model_seeds, after_from_report=from_report)
    metrics = summarize(trials, objects, chosen, setup, cfg.n_bootstrap, params.seed)
    scores = read_table(SCORES).set_index("shape_id")  # no grasp sampled: n/a, not 0
    calibration_table, metrics["calibration"] = calibration(trials, scores.graspness[scores.n_grasps > 0])
    timing = planning_timing(trials, list(chosen))

    with atomic_path(SIM_REPORT_DIR, directory=True) as out:
        write_trials_report(
            out, rows, trials, objects, calibration_table, metrics, chosen, model_seeds, SCORES.as_posix()
        )
        timing["stage_seconds"] = round(time.perf_counter() - start, 1)
        write_json(timing, out / "timing.json")
        write_json(metrics, out / "summary.json")
    write_json_files(sim_headline(metrics), SIM_METRICS)
    log.info("sim: %s; %.0f s", outcome_words(metrics, timing), time.perf_counter() - start)
