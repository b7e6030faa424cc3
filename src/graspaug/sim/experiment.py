"""The simulated robot experiment: arms (which network plans), the objects, one object's
attempts in one arm, success rates with Wilson intervals, the paired before/after comparison,
and the report's text (paper Section IV-E).

Every arm sees the same seeded drops and planner seeds (paired); ``before`` is the targeted
network of base size B at ratio 0, ``after`` the same B at the report's best ratio, once per
training seed; the optional ``antipodal`` arm plans without a network.
"""
from __future__ import annotations

import functools
import json
import logging
import os
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from graspaug.errors import StageError
from graspaug.paths import gqcnn_model_dir
from graspaug.rng import shape_rng

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


def model_path(base_size: int, ratio: float, seed: int) -> Path:
    """The targeted network of base size B at ratio R and training seed."""
    return gqcnn_model_dir("targeted", base_size, ratio, seed) / "model.pt"


def arms(ap_metrics: Path, base_size: int, ratios: Sequence[float], seeds: Sequence[int]) -> tuple[dict[str, float], bool]:
    """Arm → ratio: 0 and the report's best ratio for ``base_size`` (from ``metrics/ap.json``),
    and whether the ratio came from the report (its networks must exist for every training
    seed). When the report has no test AP for that base size (a test set with one label),
    "after" is the largest of ``ratios``, with a warning."""
    if not ap_metrics.exists():
        raise StageError(f"{ap_metrics} is missing: run `dvc repro report` first")
    summary = json.loads(ap_metrics.read_text()).get("summary", {}).get(str(base_size))
    if summary is None:
        best = float(max(ratios))
        log.warning("sim: %s has no test AP for base size %d; comparing ratio 0 with the largest ratio %g", ap_metrics, base_size, best)
    else:
        best = float(summary["best_ratio"])
    chosen = {"before": 0.0, "after": best}
    for seed in seeds:
        for ratio in chosen.values():
            if not model_path(base_size, ratio, seed).exists():
                raise StageError(f"{model_path(base_size, ratio, seed)} is missing: run `dvc repro train_gqcnn` first")
    return chosen, summary is not None


def test_shape_ids(shapes: pd.DataFrame, n: int, seed: int) -> list[str]:
    """The held-out shapes picked in the trials: a seeded choice of ``n`` from the test split of ``shapes``."""
    if n == 0:
        return []
    test = sorted(shapes.shape_id[shapes.split == "test"])
    if len(test) < n:
        raise StageError(f"sim.n_test_objects = {n} but the test split has {len(test)} shapes")
    chosen = shape_rng(seed, "sim", "test-objects").choice(len(test), size=n, replace=False)
    return [test[i] for i in sorted(chosen)]


def prepare_objects(everyday: Sequence[str], test_shapes: Sequence[str], shapes_dir: Path, mass: float, friction: float, vhacd_resolution: int):
    """(name, kind, SimObject, extents) for every object, decompositions cached."""
    from graspaug.io.meshes import mesh_path, read_mesh
    from graspaug.sim.objects import default_cache_dir, everyday_mesh, prepare_object

    cache = default_cache_dir()
    meshes = [(name, "everyday", everyday_mesh(name)) for name in everyday]
    meshes += [(shape_id, "test_shape", read_mesh(mesh_path(shapes_dir, shape_id))) for shape_id in test_shapes]
    return [(name, kind, prepare_object(name, mesh, cache, mass, friction, vhacd_resolution), mesh.extents) for name, kind, mesh in meshes]


def _policy(model: str | None, layout, sampler, cem, crop_size: int, out_size: int):
    """The planner for ``model``, loaded once per worker process and file version."""
    if model is None:
        return _cached_policy(None, None, layout, sampler, cem, crop_size, out_size)
    path = os.path.abspath(model)
    stat = os.stat(path)
    return _cached_policy(path, (stat.st_mtime_ns, stat.st_size), layout, sampler, cem, crop_size, out_size)


@functools.lru_cache(maxsize=4)
def _cached_policy(model: str | None, version, layout, sampler, cem, crop_size: int, out_size: int):
    """A :class:`graspaug.planning.Planner`: the public planner is the one the robot uses. A
    checkpoint without a model card gets the render params' crop sizes."""
    import dataclasses

    from graspaug.planning import Planner, load_planner

    if model is None:
        return Planner(None, sampler=sampler, cem=cem, check_image=False)  # Dex-Net's policy, as it was
    import torch

    torch.set_num_threads(1)
    planner = load_planner(model, sampler, cem, check_image=False)
    if planner.card.assumed:
        planner.card = dataclasses.replace(planner.card, crop_size=crop_size, out_size=out_size)
    return planner


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
        plan = lambda depth, camera, k: next(iter(policy.plan(depth, k, rng, camera_distance=camera.height)), None)  # noqa: E731
        result = run_trial(job.sim_object, drop_seed, planner=plan, layout=layout,
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


def picture(row: dict, ratio: float | None, path) -> None:
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


def mean_or_none(values: pd.Series) -> float | None:
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


def planning_timing(trials: pd.DataFrame, arms: list[str]) -> dict:
    """Planning time per grasp (s): mean, median, max over the trials, mean per arm; the stage
    fills in ``stage_seconds``."""
    planning = trials.planning_time.dropna()
    return {"planning_time_mean": float(planning.mean()) if len(planning) else None,
            "planning_time_median": float(planning.median()) if len(planning) else None,
            "planning_time_max": float(planning.max()) if len(planning) else None,
            "planning_time_by_arm": {arm: mean_or_none(trials.planning_time[trials.arm == arm]) for arm in arms},
            "trials": int(len(trials)), "stage_seconds": None}

