"""Stage ``sim``: simulated Panda pick-and-place trials with the GQ-CNN before and after augmentation.

Arms (:mod:`graspaug.experiments.sim`): ``before`` = the targeted network of base size
``sim.base_size`` at ratio 0, ``after`` = the same base size at the ratio chosen on validation AP
(``metrics/ap.json``), ``real`` = the ``real`` pool's network there (when trained), each once per
training seed of ``gqcnn.seeds``, and ``antipodal`` = a random antipodal grasp without a network.
Every object (the everyday objects of ``sim.objects``, ``sim.n_test_objects`` held-out test
shapes and the meshes of ``sim.objects_path``), with mass and friction drawn per object, is
dropped ``sim.attempts`` times from seeded poses, the same for every arm; the planner sees the
D435-like noisy depth image and the Panda tries to put the object in the bin.

Writes ``metrics/sim.json`` (per-arm rates with 95 % Wilson intervals; ``contrasts``: paired differences with a
bootstrap interval over objects; per training seed and per object; the calibration's Spearman correlation) and
``reports/sim/`` (``report.md``, ``trials.csv`` one row per attempt, ``success.csv``/``success.png`` per object,
``objects.csv``, ``calibration.csv``, ``timing.json``, ``trials/<arm>-<object>.png`` depth image with the grasp
and pick frames).
"""

from __future__ import annotations

import functools
import json
import logging
import time
from pathlib import Path

from graspaug.experiments.sim import (
    arms,
    object_jobs,
    prepare_objects,
    run_object,
    test_shape_ids,
    trial_picture,
    trials_table,
)
from graspaug.experiments.sim_report import (
    calibration,
    objects_table,
    planning_timing,
    report_text,
    success_bar_data,
    success_table,
    summarize,
    trial_setup,
)
from graspaug.io.atomic import atomic_path
from graspaug.io.tables import read_table, write_csv, write_json
from graspaug.parallel import parallel_map
from graspaug.params.base import params_model
from graspaug.params.generate import GenerateParams
from graspaug.params.gqcnn import GQCNNParams
from graspaug.params.grasps import GraspsParams
from graspaug.params.ingest import IngestParams
from graspaug.params.render import RenderParams
from graspaug.params.sim import SimParams
from graspaug.paths import AP_METRICS, SCORES, SHAPES_DIR, SHAPES_TABLE, SIM_METRICS, SIM_REPORT_DIR, gqcnn_seed_dir
from graspaug.sim.objects import folder_meshes
from graspaug.stages import StageError

log = logging.getLogger(__name__)

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
    from graspaug.plots import pick_story, success_bars

    start = time.perf_counter()
    cfg, model_seeds = params.sim, list(params.gqcnn.seeds)
    if not AP_METRICS.exists():
        raise StageError(f"{AP_METRICS} is missing: run `dvc repro report` first")
    summary = json.loads(AP_METRICS.read_text()).get("summary", {}).get(str(cfg.base_size))
    best = float(max(params.generate.ratios)) if summary is None else float(summary["best_ratio"])
    if summary is None:
        log.warning(
            "sim: %s has no AP for base size %d; comparing ratio 0 with the largest ratio %g",
            AP_METRICS,
            cfg.base_size,
            best,
        )
    seed_dirs = {seed: gqcnn_seed_dir(seed) for seed in model_seeds}
    chosen = arms(best, cfg.base_size, seed_dirs)
    test_shapes = test_shape_ids(read_table(SHAPES_TABLE), cfg.n_test_objects, params.seed)
    try:
        user, skipped = (
            ([], {})
            if cfg.objects_path is None
            else folder_meshes(
                Path(cfg.objects_path), params.ingest.surface, params.ingest.max_faces, params.ingest.max_file_mb
            )
        )
    except ValueError as exc:  # an empty or unreadable folder: one line, not a traceback
        raise StageError(str(exc)) from None
    objects = prepare_objects(
        cfg.objects,
        test_shapes,
        SHAPES_DIR,
        cfg.physics,
        params.seed,
        cfg.vhacd_resolution,
        user,
        workers=params.workers,
    )
    jobs = object_jobs(objects, chosen, cfg.base_size, seed_dirs, cfg.attempts, params.seed, cfg.n_pictures)
    log.info(
        "sim: %d objects × %d attempts; arms %s × %d training seeds (after = ratio %g); %d skipped meshes",
        len(objects),
        cfg.attempts,
        ", ".join(chosen),
        len(model_seeds),
        chosen["after"][1],
        len(skipped),
    )
    work = functools.partial(
        run_object,
        layout=cfg.cell,
        hand=cfg.hand,
        sampler=cfg.sampler,
        cem=cfg.cem,
        crop_size=params.render.crop.crop_size,
        out_size=params.render.crop.out_size,
        trial_settings=cfg.trial,
        sensor=cfg.sensor,
    )
    rows = [row for rows in parallel_map(work, jobs, params.workers, "sim") for row in rows]
    trials = trials_table(rows, chosen)

    setup = trial_setup(cfg, objects, skipped, model_seeds, after_from_report=summary is not None)
    metrics = summarize(trials, objects, chosen, setup, cfg.n_bootstrap, params.seed)
    scores = read_table(SCORES).set_index("shape_id")  # no grasp sampled: n/a, not 0
    calibration_table, metrics["calibration"] = calibration(trials, scores.graspness[scores.n_grasps > 0])
    timing = planning_timing(trials, list(chosen))

    with atomic_path(SIM_REPORT_DIR, directory=True) as out:
        write_csv(trials.drop(columns=["planning_time"]), out / "trials.csv")
        write_csv(objects_table(objects), out / "objects.csv")
        write_csv(calibration_table, out / "calibration.csv")
        write_csv(success_table(metrics, list(chosen)), out / "success.csv")
        success_bars(
            *success_bar_data(metrics, chosen),
            out / "success.png",
            f"Pick success per object, B = {cfg.base_size}, training seeds {model_seeds} (95% Wilson intervals)",
        )
        (out / "trials").mkdir()
        for row in rows:
            if row["_depth"] is not None:
                path = out / "trials" / f"{row['arm']}-{row['object']}.png"
                pick_story(**trial_picture(row, chosen[row["arm"]][1]), path=path)
        (out / "report.md").write_text(report_text(metrics, trials, calibration_table, SCORES.as_posix()))
        timing["stage_seconds"] = round(time.perf_counter() - start, 1)
        write_json(timing, out / "timing.json")
    write_json(metrics, SIM_METRICS)
    rates = ", ".join(f"{arm} {a['successes']}/{a['attempts']}" for arm, a in metrics["arms"].items())
    contrasts = ", ".join(
        f"{n} {c['mean']:+.2f} [{c['ci_low']:+.2f}, {c['ci_high']:+.2f}]" for n, c in metrics["contrasts"].items()
    )
    log.info(
        "sim: %s; %s; planning %.3f s per grasp (max %.3f); %.0f s",
        rates,
        contrasts,
        timing["planning_time_mean"] or 0,
        timing["planning_time_max"] or 0,
        time.perf_counter() - start,
    )
