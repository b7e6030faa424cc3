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
import json
import logging
import os
import time
from dataclasses import dataclass

import numpy as np
import pandas as pd

from graspaug.config import Params
from graspaug.io.atomic import atomic_path
from graspaug.io.tables import read_table, write_csv, write_json
from graspaug.parallel import parallel_map
from graspaug.paths import AP_METRICS, SHAPES_DIR, SHAPES_TABLE, SIM_METRICS, SIM_REPORT_DIR, gqcnn_model_dir
from graspaug.render.camera import Intrinsics
from graspaug.rng import shape_rng
from graspaug.stages import StageError

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class ObjectJob:
    """One object's attempts in one arm (a worker's unit of work)."""

    arm: str
    seed: int  # the network's training seed
    model: str | None  # path of model.pt; None: the antipodal reference arm (no network)
    name: str
    kind: str  # everyday | test_shape
    sim_object: object  # graspaug.sim.objects.SimObject
    drop_seeds: tuple[int, ...]
    plan_seeds: tuple[int, ...]
    record: bool


def arms(params: Params) -> tuple[dict[str, float], bool]:
    """Arm → ratio: 0 and the report's best ratio for ``sim.base_size``, and whether the ratio
    came from the report (its networks must exist for every training seed). When the report has no test AP for that base size (a
    test set with one label), "after" is the largest ratio, with a warning."""
    if not AP_METRICS.exists():
        raise StageError(f"{AP_METRICS} is missing: run `dvc repro report` first")
    base = params.sim.base_size
    summary = json.loads(AP_METRICS.read_text()).get("summary", {}).get(str(base))
    if summary is None:
        best = float(max(params.generate.ratios))
        log.warning("sim: %s has no test AP for base size %d; comparing ratio 0 with the largest ratio %g", AP_METRICS, base, best)
    else:
        best = float(summary["best_ratio"])
    ratios = {"before": 0.0, "after": best}
    for seed in params.gqcnn.seeds:
        for ratio in ratios.values():
            if not model_path(params, ratio, seed).exists():
                raise StageError(f"{model_path(params, ratio, seed)} is missing: run `dvc repro train_gqcnn` first")
    return ratios, summary is not None


def model_path(params: Params, ratio: float, seed: int):
    return gqcnn_model_dir("targeted", params.sim.base_size, ratio, seed) / "model.pt"


def test_shape_ids(params: Params) -> list[str]:
    """The held-out shapes picked in the trials: a seeded choice from the test split."""
    if params.sim.n_test_objects == 0:
        return []
    shapes = read_table(SHAPES_TABLE)
    test = sorted(shapes.shape_id[shapes.split == "test"])
    if len(test) < params.sim.n_test_objects:
        raise StageError(f"sim.n_test_objects = {params.sim.n_test_objects} but the test split has {len(test)} shapes")
    chosen = shape_rng(params.seed, "sim", "test-objects").choice(len(test), size=params.sim.n_test_objects, replace=False)
    return [test[i] for i in sorted(chosen)]


def prepare_objects(params: Params):
    """(name, kind, SimObject, extents) for every object, decompositions cached."""
    from graspaug.io.meshes import mesh_path, read_mesh
    from graspaug.sim.objects import default_cache_dir, everyday_mesh, prepare_object

    cfg, cache = params.sim, default_cache_dir()
    meshes = [(name, "everyday", everyday_mesh(name)) for name in cfg.objects]
    meshes += [(shape_id, "test_shape", read_mesh(mesh_path(SHAPES_DIR, shape_id))) for shape_id in test_shape_ids(params)]
    return [(name, kind, prepare_object(name, mesh, cache, cfg.object_mass, cfg.object_friction, cfg.vhacd_resolution), mesh.extents)
            for name, kind, mesh in meshes]


def settings(params: Params):
    """The library settings that params.sim describes."""
    from graspaug.sim.panda import HandSettings
    from graspaug.sim.policy import CEMSettings, SamplerSettings
    from graspaug.sim.scene import CellLayout

    cfg = params.sim
    intrinsics = Intrinsics(width=cfg.image_width, height=cfg.image_height, fx=cfg.focal_length, fy=cfg.focal_length,
                            cx=(cfg.image_width - 1) / 2, cy=(cfg.image_height - 1) / 2)
    layout = CellLayout(camera_height=cfg.camera_height, intrinsics=intrinsics, table_friction=cfg.table_friction)
    hand = HandSettings(grip_force=cfg.grip_force, finger_friction=cfg.finger_friction)
    sampler = SamplerSettings(friction_coef=cfg.friction_coef, depth_grad_thresh=cfg.depth_grad_thresh,
                              min_dist_from_boundary=cfg.min_dist_from_boundary, min_depth_offset=cfg.min_depth_offset,
                              max_depth_offset=cfg.max_depth_offset, max_width=params.grasps.max_width)
    cem = CEMSettings(num_seed_samples=cfg.seed_samples, num_iters=cfg.cem_iters, elite_fraction=cfg.elite_fraction,
                      gmm_components=cfg.gmm_components, num_gmm_samples=cfg.gmm_samples)
    return layout, hand, sampler, cem


def _policy(model: str | None, layout, sampler, cem, crop_size: int, out_size: int):
    """The planner for ``model``, loaded once per worker process and file version."""
    if model is None:
        return _cached_policy(None, None, layout, sampler, cem, crop_size, out_size)
    path = os.path.abspath(model)
    stat = os.stat(path)
    return _cached_policy(path, (stat.st_mtime_ns, stat.st_size), layout, sampler, cem, crop_size, out_size)


@functools.lru_cache(maxsize=4)
def _cached_policy(model: str | None, version, layout, sampler, cem, crop_size: int, out_size: int):
    from graspaug.sim.policy import RandomAntipodalPolicy

    if model is None:
        return RandomAntipodalPolicy(layout.intrinsics, sampler)
    import torch

    from graspaug.io.checkpoints import load_gqcnn
    from graspaug.render.crops import CropGeometry
    from graspaug.sim.policy import CrossEntropyGraspPolicy

    torch.set_num_threads(1)
    return CrossEntropyGraspPolicy(load_gqcnn(model), layout.intrinsics, sampler, cem, CropGeometry(crop_size, out_size))


def run_object(job: ObjectJob, layout, hand, sampler, cem, crop_size: int, out_size: int, trial_settings=None) -> list[dict]:
    """Every attempt of one object in one arm: a row per attempt (plus depth and frames for the
    first attempt when ``job.record``)."""
    from graspaug.sim.trials import TrialSettings, run_trial

    trial_settings = trial_settings or TrialSettings()
    policy = _policy(job.model, layout, sampler, cem, crop_size, out_size)
    rows = []
    for attempt, (drop_seed, plan_seed) in enumerate(zip(job.drop_seeds, job.plan_seeds)):
        rng = np.random.default_rng(plan_seed)
        record = job.record and attempt == 0
        result = run_trial(job.sim_object, drop_seed, planner=lambda depth, camera, k: policy.plan(depth, rng), layout=layout,
                           hand=hand, settings=trial_settings, record=record)
        g = result.image_grasp or {}
        rows.append({
            "arm": job.arm, "seed": job.seed, "object": job.name, "kind": job.kind, "attempt": attempt, "drop_seed": drop_seed,
            "outcome": result.outcome, "success": result.success, "quality": result.quality, "candidates": result.candidates,
            "u": g.get("u"), "v": g.get("v"), "angle": g.get("angle"), "depth": g.get("depth"), "width_px": g.get("width_px"),
            "grasp_x": None if result.grasp_center is None else result.grasp_center[0],
            "grasp_y": None if result.grasp_center is None else result.grasp_center[1],
            "grasp_z": None if result.grasp_center is None else result.grasp_center[2],
            "jaw_angle": result.jaw_angle, "planning_time": result.planning_time,
            "_depth": result.depth, "_frames": result.frames,
        })
    return rows


def rate_summary(outcomes: pd.Series) -> dict:
    from graspaug.sim.stats import wilson_interval

    k, n = int(outcomes.sum()), int(len(outcomes))
    low, high = wilson_interval(k, n)
    return {"successes": k, "attempts": n, "success_rate": round(k / n, 5) if n else None, "wilson_low": round(low, 5), "wilson_high": round(high, 5)}


def _picture(row: dict, ratio: float | None, path) -> None:
    from graspaug.plots import pick_story

    depth = row["_depth"]
    h, w = depth.shape
    jaw = None
    if row["u"] is not None:
        half = 0.5 * row["width_px"] * np.array([np.cos(row["angle"]), np.sin(row["angle"])])
        center = np.array([row["u"], row["v"]])
        jaw = np.stack([center - half, center + half])
        cu, cv = int(round(row["u"])), int(round(row["v"]))
    else:
        cu, cv = w // 2, h // 2
    r = min(80, h // 2, w // 2)
    u0, v0 = int(np.clip(cu - r, 0, w - 2 * r)), int(np.clip(cv - r, 0, h - 2 * r))
    quality = "no grasp found" if row["quality"] is None else ("random" if np.isnan(row["quality"]) else f"Q = {row['quality']:.3f}")
    network = "random antipodal grasp, no network" if ratio is None else f"ratio {ratio:g}, training seed {row['seed']}"
    title = f"{row['object']}, arm {row['arm']} ({network}), attempt 0: {quality} → {row['outcome']}"
    pick_story(depth, jaw, (u0, v0, u0 + 2 * r, v0 + 2 * r), row["_frames"], path, title)


def _mean_or_none(values: pd.Series) -> float | None:
    values = values.dropna()
    return float(values.mean()) if len(values) else None


def compare(trials: pd.DataFrame) -> dict:
    """Before vs after on the attempts of ``trials``: both rates, the difference, and the exact
    McNemar test on the attempts paired by seed, object and drop."""
    from graspaug.sim.stats import paired_test

    out = {arm: rate_summary(trials.success[trials.arm == arm]) for arm in ("before", "after")}
    paired = trials.pivot_table(index=["seed", "object", "attempt"], columns="arm", values="success", aggfunc="first")
    if paired.isna().any().any():
        raise StageError("sim: an attempt is missing from one arm; the arms cannot be paired")
    out["difference"] = round(out["after"]["success_rate"] - out["before"]["success_rate"], 5)
    out["paired"] = paired_test(paired["before"].to_numpy(bool), paired["after"].to_numpy(bool))
    return out


def report_text(metrics: dict, trials: pd.DataFrame) -> str:
    setup, seeds = metrics["setup"], metrics["per_seed"]
    before, after, test, diff = metrics["arms"]["before"], metrics["arms"]["after"], metrics["paired"], metrics["difference"]
    lines = [
        "# Simulated robot trials: GQ-CNN before vs after augmentation",
        "",
        f"Franka Panda in pybullet, overhead depth camera {setup['camera_height']} m above the table, {setup['objects']} objects × "
        f"{setup['attempts']} seeded drops, the same drops for every network; networks of training seeds {setup['model_seeds']}. "
        "Success = the object ends inside the bin.",
        "",
        "| arm | network | successes | rate | 95% Wilson interval |",
        "|---|---|---|---|---|",
    ]
    for arm in ("before", "after"):
        a = metrics["arms"][arm]
        lines.append(f"| {arm} | B = {setup['base_size']}, ratio {a['ratio']:g} | {a['successes']}/{a['attempts']} | "
                     f"{a['success_rate']:.2f} | [{a['wilson_low']:.2f}, {a['wilson_high']:.2f}] |")
    if "antipodal_reference" in metrics:
        r = metrics["antipodal_reference"]
        lines.append(f"| reference | none: a random antipodal seed grasp | {r['successes']}/{r['attempts']} | {r['success_rate']:.2f} | "
                     f"[{r['wilson_low']:.2f}, {r['wilson_high']:.2f}] |")
    if len(seeds) > 1:
        lines += ["", "| training seed | before | after | difference | McNemar p |", "|---|---|---|---|---|"]
        for seed, row in seeds.items():
            lines.append(f"| {seed} | {row['before']['successes']}/{row['before']['attempts']} | {row['after']['successes']}/"
                         f"{row['after']['attempts']} | {row['difference']:+.2f} | {row['paired']['p_value']:.3g} |")
    lines += ["", "| object | kind | before | after |", "|---|---|---|---|"]
    for name, row in metrics["per_object"].items():
        b, a = row["before"], row["after"]
        lines.append(f"| {name} | {row['kind']} | {b['successes']}/{b['attempts']} | {a['successes']}/{a['attempts']} |")
    counts = trials.groupby(["arm", "outcome"]).size().unstack(fill_value=0)
    lines += ["", "Outcomes (no_grasp: no antipodal pair on the image; not_lifted: the object stayed on the table; "
              "dropped: lost on the way; outside_bin: released but not in the bin):", "",
              "| arm | " + " | ".join(counts.columns) + " |", "|---|" + "---|" * len(counts.columns)]
    for arm, row in counts.iterrows():
        lines.append(f"| {arm} | " + " | ".join(str(int(v)) for v in row) + " |")
    lines += ["", "## Verdict", ""]
    if metrics["same_network"]:
        lines.append(f"The report's best ratio for B = {setup['base_size']} is 0, so \"after\" is the same network as "
                     "\"before\": augmentation brought nothing to test here.")
        return "\n".join(lines) + "\n"
    word = "rose" if diff > 0 else ("fell" if diff < 0 else "did not change")
    lines.append(f"The success rate {word} after augmentation ({before['success_rate']:.2f} → {after['success_rate']:.2f}, {diff:+.2f}). "
                 f"On the same drops \"after\" alone succeeded {test['only_after']} times and \"before\" alone "
                 f"{test['only_before']} times (exact McNemar p = {test['p_value']:.3g}).")
    if test["p_value"] >= 0.05:
        lines.append("The difference is within chance at the 5% level: no evidence either way.")
    elif diff > 0:
        lines.append("Augmentation helped the simulated robot beyond chance (5% level).")
    else:
        lines.append("Augmentation made the simulated robot worse, beyond chance (5% level); the paper's 68% → 86% "
                     "(real Panda) does not reproduce here.")
    signs = {np.sign(row["difference"]) for row in seeds.values()}
    if len(seeds) == 1:
        lines.append("These are two particular networks (one training seed): how much the comparison changes with the seed is "
                     "not measured here; `gqcnn.seeds: [0, 1, 2]` (profiles/study.yaml) repeats it per seed.")
    elif len(signs - {0.0}) > 1:
        lines.append("The sign of the difference changes with the training seed: the networks' seed-to-seed spread is larger "
                     "than the effect of augmentation on the robot.")
    return "\n".join(lines) + "\n"


def run(params: Params) -> None:
    from graspaug.plots import success_bars

    start = time.perf_counter()
    cfg, model_seeds = params.sim, list(params.gqcnn.seeds)
    ratios, from_report = arms(params)
    objects = prepare_objects(params)
    layout, hand, sampler, cem = settings(params)
    jobs = []
    for index, (name, kind, sim_object, _) in enumerate(objects):
        drop_seeds = tuple(int(shape_rng(params.seed, name, f"sim-drop-{a}").integers(2**31 - 1)) for a in range(cfg.attempts))
        plan_seeds = tuple(int(shape_rng(params.seed, name, f"sim-plan-{a}").integers(2**31 - 1)) for a in range(cfg.attempts))
        for seed in model_seeds:
            for arm, ratio in ratios.items():
                record = index < cfg.n_pictures and seed == model_seeds[0]
                jobs.append(ObjectJob(arm, seed, str(model_path(params, ratio, seed)), name, kind, sim_object, drop_seeds, plan_seeds, record))
        if cfg.antipodal_arm:  # no network, so no training seed: once
            jobs.append(ObjectJob("antipodal", -1, None, name, kind, sim_object, drop_seeds, plan_seeds, index < cfg.n_pictures))
    log.info("sim: %d objects × %d attempts × 2 arms × %d training seeds (after = ratio %g)", len(objects), cfg.attempts,
             len(model_seeds), ratios["after"])
    from graspaug.sim.trials import TrialSettings

    work = functools.partial(run_object, layout=layout, hand=hand, sampler=sampler, cem=cem, crop_size=params.render.crop_size,
                             out_size=params.render.out_size, trial_settings=TrialSettings(drop_offset=cfg.drop_offset))
    rows = [row for rows in parallel_map(work, jobs, params.workers, "sim") for row in rows]
    trials = pd.DataFrame([{k: v for k, v in row.items() if not k.startswith("_")} for row in rows])
    trials["ratio"] = trials.arm.map(ratios)
    reference = trials[trials.arm == "antipodal"]
    trials = trials[trials.arm != "antipodal"]

    pooled = compare(trials)
    metrics = {
        "setup": {"base_size": cfg.base_size, "after_ratio_from_report": from_report, "objects": len(objects), "attempts": cfg.attempts,
                  "test_shapes": [name for name, kind, _, _ in objects if kind == "test_shape"], "camera_height": cfg.camera_height,
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

    planning = trials.planning_time.dropna()
    timing = {"planning_time_mean": float(planning.mean()) if len(planning) else None,
              "planning_time_median": float(planning.median()) if len(planning) else None,
              "planning_time_max": float(planning.max()) if len(planning) else None,
              "planning_time_by_arm": {arm: _mean_or_none(trials.planning_time[trials.arm == arm]) for arm in ratios},
              "trials": int(len(trials)), "stage_seconds": None}

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
                _picture(row, ratios.get(row["arm"]), out / "trials" / f"{row['arm']}-{row['object']}.png")
        (out / "report.md").write_text(report_text(metrics, trials))
        timing["stage_seconds"] = round(time.perf_counter() - start, 1)
        write_json(timing, out / "timing.json")
    write_json(metrics, SIM_METRICS)
    b, a = metrics["arms"]["before"], metrics["arms"]["after"]
    log.info("sim: before %d/%d (%.2f), after %d/%d (%.2f), McNemar p = %.3f; planning %.3f s per grasp (max %.3f); %.0f s",
             b["successes"], b["attempts"], b["success_rate"], a["successes"], a["attempts"], a["success_rate"], metrics["paired"]["p_value"],
             timing["planning_time_mean"] or 0, timing["planning_time_max"] or 0, time.perf_counter() - start)
