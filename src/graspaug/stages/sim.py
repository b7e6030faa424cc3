"""Stage ``sim``: simulated Panda pick-and-place trials with the GQ-CNN before and after augmentation.

Arms: ``before`` = the targeted network of base size ``sim.base_size`` at ratio 0, ``after`` =
the same base size at the best ratio of ``metrics/ap.json``, each once per training seed of
``gqcnn.seeds``. Every object (the everyday objects of ``sim.objects`` and
``sim.n_test_objects`` held-out test shapes) is dropped ``sim.attempts`` times from seeded
poses, the same for every arm and seed; each network plans one grasp per drop on the overhead
depth image and the Panda tries to put the object in the bin.

Writes ``metrics/sim.json`` (success per arm, per training seed and per object with 95 % Wilson
intervals, the paired McNemar test), ``reports/sim/`` (``report.md``, ``trials.csv`` one row per attempt,
``success.csv``/``success.png`` per object, ``objects.csv``, ``timing.json`` planning and stage
times, ``trials/<arm>-<object>.png`` depth image with the grasp and pick frames).
"""
from __future__ import annotations

import functools
import logging
import time

import numpy as np
import pandas as pd

from graspaug.config import Params
from graspaug.io.atomic import atomic_path
from graspaug.io.tables import read_table, write_csv, write_json
from graspaug.parallel import parallel_map
from graspaug.paths import AP_METRICS, SHAPES_DIR, SHAPES_TABLE, SIM_METRICS, SIM_REPORT_DIR
from graspaug.rng import shape_rng
from graspaug.sim.experiment import (
    ObjectJob, arms, compare, model_path, picture, planning_timing, prepare_objects, rate_summary, report_text, run_object, test_shape_ids,
)

log = logging.getLogger(__name__)


def run(params: Params) -> None:
    from graspaug.plots import success_bars

    start = time.perf_counter()
    cfg, model_seeds = params.sim, list(params.gqcnn.seeds)
    ratios, from_report = arms(AP_METRICS, cfg.base_size, params.generate.ratios, model_seeds)
    test_shapes = test_shape_ids(read_table(SHAPES_TABLE), cfg.n_test_objects, params.seed)
    objects = prepare_objects(cfg.objects, test_shapes, SHAPES_DIR, cfg.object_mass, cfg.object_friction, cfg.vhacd_resolution)
    jobs = []
    for index, (name, kind, sim_object, _) in enumerate(objects):
        drop_seeds = tuple(int(shape_rng(params.seed, name, f"sim-drop-{a}").integers(2**31 - 1)) for a in range(cfg.attempts))
        plan_seeds = tuple(int(shape_rng(params.seed, name, f"sim-plan-{a}").integers(2**31 - 1)) for a in range(cfg.attempts))
        for seed in model_seeds:
            for arm, ratio in ratios.items():
                record = index < cfg.n_pictures and seed == model_seeds[0]
                jobs.append(ObjectJob(arm, seed, str(model_path(cfg.base_size, ratio, seed)), name, kind, sim_object, drop_seeds, plan_seeds, record))
        if cfg.antipodal_arm:  # no network, so no training seed: once
            jobs.append(ObjectJob("antipodal", -1, None, name, kind, sim_object, drop_seeds, plan_seeds, index < cfg.n_pictures))
    log.info("sim: %d objects × %d attempts × 2 arms × %d training seeds (after = ratio %g)", len(objects), cfg.attempts,
             len(model_seeds), ratios["after"])
    work = functools.partial(run_object, layout=cfg.cell, hand=cfg.hand, sampler=cfg.sampler, cem=cfg.cem, crop_size=params.render.crop.crop_size,
                             out_size=params.render.crop.out_size, trial_settings=cfg.trial)
    rows = [row for rows in parallel_map(work, jobs, params.workers, "sim") for row in rows]
    trials = pd.DataFrame([{k: v for k, v in row.items() if not k.startswith("_")} for row in rows])
    trials["ratio"] = trials.arm.map(ratios)
    reference = trials[trials.arm == "antipodal"]
    trials = trials[trials.arm != "antipodal"]

    pooled = compare(trials)
    metrics = {
        "setup": {"base_size": cfg.base_size, "after_ratio_from_report": from_report, "objects": len(objects), "attempts": cfg.attempts,
                  "test_shapes": [name for name, kind, _, _ in objects if kind == "test_shape"], "camera_height": cfg.cell.camera_height,
                  "model_seeds": model_seeds},
        "arms": {arm: {"ratio": ratio, **pooled[arm]} for arm, ratio in ratios.items()},
        "difference": pooled["difference"],
        "paired": pooled["paired"],
        "same_network": ratios["before"] == ratios["after"],
        "per_seed": {str(seed): compare(trials[trials.seed == seed]) for seed in model_seeds},
        "per_object": {},
    }
    if cfg.antipodal_arm:
        metrics["antipodal_reference"] = rate_summary(reference.success)
    for name, kind, _, _ in objects:
        sel = trials.object == name
        metrics["per_object"][name] = {"kind": kind, **{arm: rate_summary(trials.success[sel & (trials.arm == arm)]) for arm in ratios}}
        if cfg.antipodal_arm:
            metrics["per_object"][name]["antipodal"] = rate_summary(reference.success[reference.object == name])

    timing = planning_timing(trials, list(ratios))

    with atomic_path(SIM_REPORT_DIR, directory=True) as out:
        write_csv(pd.concat([trials, reference]).drop(columns=["planning_time"]), out / "trials.csv")
        write_csv(pd.DataFrame([{"object": name, "kind": kind, "extent_x": e[0], "extent_y": e[1], "extent_z": e[2],
                                 "mass": cfg.object_mass, "friction": cfg.object_friction,
                                 "convex_hulls": ("\n" + so.collision.read_text()).count("\no "), "collision_file": so.collision.name}
                                for name, kind, so, e in objects]), out / "objects.csv")
        per_object = pd.DataFrame([{"object": name, **{arm: row[arm]["success_rate"] for arm in [*ratios, "antipodal"] if arm in row}}
                                   for name, row in metrics["per_object"].items()])
        write_csv(per_object, out / "success.csv")
        names = [*metrics["per_object"], "all"]
        bars = {}
        labels = {arm: f"{arm} (ratio {ratio:g})" for arm, ratio in ratios.items()}
        totals = dict(metrics["arms"])
        if cfg.antipodal_arm:
            labels["antipodal"], totals["antipodal"] = "random antipodal grasp (no network)", metrics["antipodal_reference"]
        for arm, label in labels.items():
            stats = [metrics["per_object"][n][arm] for n in names[:-1]] + [totals[arm]]
            bars[label] = tuple(np.array([s[key] for s in stats]) for key in ("success_rate", "wilson_low", "wilson_high"))
        success_bars(names, bars, out / "success.png",
                     f"Pick success per object, B = {cfg.base_size}, training seeds {model_seeds} (95% Wilson intervals)")
        (out / "trials").mkdir()
        for row in rows:
            if row["_depth"] is not None:
                picture(row, ratios.get(row["arm"]), out / "trials" / f"{row['arm']}-{row['object']}.png")
        (out / "report.md").write_text(report_text(metrics, trials))
        timing["stage_seconds"] = round(time.perf_counter() - start, 1)
        write_json(timing, out / "timing.json")
    write_json(metrics, SIM_METRICS)
    b, a = metrics["arms"]["before"], metrics["arms"]["after"]
    log.info("sim: before %d/%d (%.2f), after %d/%d (%.2f), McNemar p = %.3f; planning %.3f s per grasp (max %.3f); %.0f s",
             b["successes"], b["attempts"], b["success_rate"], a["successes"], a["attempts"], a["success_rate"], metrics["paired"]["p_value"],
             timing["planning_time_mean"] or 0, timing["planning_time_max"] or 0, time.perf_counter() - start)
