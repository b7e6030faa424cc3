"""Stage ``sim``: simulated Panda pick-and-place trials with the GQ-CNN before and after augmentation.

Arms (:mod:`graspaug.sim.experiment`): ``before`` = the targeted network of base size
``sim.base_size`` at ratio 0, ``after`` = the same base size at the ratio chosen on validation AP
(``metrics/ap.json``), ``real`` = the ``real`` pool's network there (when trained), each once per
training seed of ``gqcnn.seeds``, and ``antipodal`` = a random antipodal grasp without a network.
Every object (the everyday objects of ``sim.objects``, ``sim.n_test_objects`` held-out test
shapes and the meshes of ``sim.objects_path``), with mass and friction drawn per object, is
dropped ``sim.attempts`` times from seeded poses, the same for every arm; the planner sees the
D435-like noisy depth image and the Panda tries to put the object in the bin.

Writes ``metrics/sim.json`` (per-arm rates with 95 % Wilson intervals; ``contrasts``: paired
differences with a bootstrap interval over objects; per training seed and per object; the
calibration's Spearman correlation) and ``reports/sim/`` (``report.md``, ``trials.csv`` one row per
attempt, ``success.csv``/``success.png`` per object, ``objects.csv``, ``calibration.csv``,
``timing.json``, ``trials/<arm>-<object>.png`` depth image with the grasp and pick frames).
"""
from __future__ import annotations

import functools
import logging
import time
from pathlib import Path

import numpy as np
import pandas as pd

from graspaug.config import Params
from graspaug.io.atomic import atomic_path
from graspaug.io.tables import read_table, write_csv, write_json
from graspaug.parallel import parallel_map
from graspaug.paths import AP_METRICS, SCORES, SHAPES_DIR, SHAPES_TABLE, SIM_METRICS, SIM_REPORT_DIR
from graspaug.sim.analysis import calibration, planning_timing, report_text
from graspaug.sim.experiment import arms, object_jobs, picture, prepare_objects, run_object, summarize, test_shape_ids
from graspaug.sim.objects import folder_meshes
from graspaug.stages import StageError

log = logging.getLogger(__name__)


def run(params: Params) -> None:
    from graspaug.plots import success_bars

    start = time.perf_counter()
    cfg, model_seeds = params.sim, list(params.gqcnn.seeds)
    chosen, from_report = arms(AP_METRICS, cfg.base_size, params.generate.ratios, model_seeds)
    test_shapes = test_shape_ids(read_table(SHAPES_TABLE), cfg.n_test_objects, params.seed)
    try:
        user, skipped = ([], {}) if cfg.objects_path is None else folder_meshes(
            Path(cfg.objects_path), params.ingest.surface, params.ingest.max_faces, params.ingest.max_file_mb)
    except ValueError as exc:  # an empty or unreadable folder: one line, not a traceback
        raise StageError(str(exc)) from None
    objects = prepare_objects(cfg.objects, test_shapes, SHAPES_DIR, cfg.physics, params.seed, cfg.vhacd_resolution, user, workers=params.workers)
    jobs = object_jobs(objects, chosen, cfg.base_size, model_seeds, cfg.attempts, params.seed, cfg.n_pictures)
    log.info("sim: %d objects × %d attempts; arms %s × %d training seeds (after = ratio %g); %d skipped meshes", len(objects), cfg.attempts,
             ", ".join(chosen), len(model_seeds), chosen["after"][1], len(skipped))
    work = functools.partial(run_object, layout=cfg.cell, hand=cfg.hand, sampler=cfg.sampler, cem=cfg.cem, crop_size=params.render.crop.crop_size,
                             out_size=params.render.crop.out_size, trial_settings=cfg.trial, sensor=cfg.sensor)
    rows = [row for rows in parallel_map(work, jobs, params.workers, "sim") for row in rows]
    trials = pd.DataFrame([{k: v for k, v in row.items() if not k.startswith("_")} for row in rows])
    trials["ratio"] = trials.arm.map({arm: ratio for arm, (_, ratio) in chosen.items()})

    setup = {"base_size": cfg.base_size, "after_ratio_from_report": from_report, "objects": len(objects), "attempts": cfg.attempts,
             "test_shapes": [o.name for o in objects if o.kind == "test_shape"], "user_objects": [o.name for o in objects if o.kind == "user"],
             "skipped_meshes": skipped, "camera_height": cfg.cell.camera_height, "sensor_noise": cfg.sensor.enabled, "model_seeds": model_seeds}
    metrics = summarize(trials, objects, chosen, setup, cfg.n_bootstrap, params.seed)
    scores = read_table(SCORES).set_index("shape_id")
    calibration_table, metrics["calibration"] = calibration(trials, scores.graspness[scores.n_grasps > 0])  # no grasp sampled: n/a, not 0
    timing = planning_timing(trials, list(chosen))

    with atomic_path(SIM_REPORT_DIR, directory=True) as out:
        write_csv(trials.drop(columns=["planning_time"]), out / "trials.csv")
        write_csv(pd.DataFrame([{"object": o.name, "kind": o.kind, "extent_x": o.extents[0], "extent_y": o.extents[1], "extent_z": o.extents[2],
                                 "density": round(o.density, 1), "mass": o.body.mass, "friction": o.body.lateral_friction,
                                 "convex_hulls": ("\n" + o.body.collision.read_text()).count("\no "), "collision_file": o.body.collision.name}
                                for o in objects]), out / "objects.csv")
        write_csv(calibration_table, out / "calibration.csv")
        write_csv(pd.DataFrame([{"object": name, **{arm: row[arm]["success_rate"] for arm in chosen}} for name, row in metrics["per_object"].items()]),
                  out / "success.csv")
        names = [*metrics["per_object"], "all"]
        bars = {}
        for arm, (pool, ratio) in chosen.items():
            label = "random antipodal grasp (no network)" if pool is None else f"{arm} ({pool}, ratio {ratio:g})"
            stats = [metrics["per_object"][n][arm] for n in names[:-1]] + [metrics["arms"][arm]]
            bars[label] = tuple(np.array([s[key] for s in stats]) for key in ("success_rate", "wilson_low", "wilson_high"))
        success_bars(names, bars, out / "success.png",
                     f"Pick success per object, B = {cfg.base_size}, training seeds {model_seeds} (95% Wilson intervals)")
        (out / "trials").mkdir()
        for row in rows:
            if row["_depth"] is not None:
                picture(row, chosen[row["arm"]][1], out / "trials" / f"{row['arm']}-{row['object']}.png")
        (out / "report.md").write_text(report_text(metrics, trials, calibration_table))
        timing["stage_seconds"] = round(time.perf_counter() - start, 1)
        write_json(timing, out / "timing.json")
    write_json(metrics, SIM_METRICS)
    rates = ", ".join(f"{arm} {a['successes']}/{a['attempts']}" for arm, a in metrics["arms"].items())
    contrasts = ", ".join(f"{n} {c['mean']:+.2f} [{c['ci_low']:+.2f}, {c['ci_high']:+.2f}]" for n, c in metrics["contrasts"].items())
    log.info("sim: %s; %s; planning %.3f s per grasp (max %.3f); %.0f s", rates, contrasts, timing["planning_time_mean"] or 0,
             timing["planning_time_max"] or 0, time.perf_counter() - start)
