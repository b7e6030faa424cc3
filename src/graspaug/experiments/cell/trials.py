"""The robot trials: which networks each arm uses, the test objects, the pick attempts in pybullet and their table."""

from __future__ import annotations

import functools
import logging
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from graspaug.errors import DataError
from graspaug.experiments.cell.picks import ORACLE  # the arm of the best grasp on the true mesh (sim.oracle)
from graspaug.rng import shape_rng
from graspaug.sim.objects import PreparedObject, prepare_objects
from graspaug.training.variants import network_variant

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class ObjectJob:
    """One object's attempts in one arm (a worker's unit of work)."""

    arm: str
    seed: int  # the network's training seed; -1 for the antipodal arm
    model: str | None  # path of model.pt; None: the antipodal reference arm (no network)
    name: str
    kind: str  # everyday | test_shape | user
    sim_object: object  # graspaug.sim.objects.SimObject
    drop_seeds: tuple[int, ...]
    plan_seeds: tuple[int, ...]
    record: bool
    #: (arm, model.pt) of networks that also score each executed grasp (its success probability in ``score_<arm>``):
    #: every network rates the same grasps, so their ranking of the cell's outcomes can be compared
    scorers: tuple[tuple[str, str], ...] = ()
    #: the paper's protocol: every attempt starts from this resting pose (position (3,) m, quaternion (x, y, z, w)),
    #: the drop seeds drawing only the sensor's noise; None: each attempt is a fresh drop
    placement: tuple | None = None


def model_path(seed_dir: Path, base_size: int, ratio: float, pool: str = "targeted") -> Path:
    """The network (``model.pt``) of ``pool`` at base size B and ratio R in its training seed's
    folder ``seed_dir``."""
    return Path(seed_dir) / network_variant(pool, base_size, ratio).name / "model.pt"


#: What an arm plans with: (pool, ratio, base size) of its network, or (None, None, None) without one.
ArmNetwork = tuple[str | None, float | None, int | None]


def arms(
    best_ratio: float, base_size: int, seed_dirs: Mapping[int, Path], base_sizes: Sequence[int] = ()
) -> dict[str, ArmNetwork]:
    """Arm → (pool, ratio, base size): ``before`` (targeted, 0, B), ``after`` (targeted, ``best_ratio``:
    the ratio chosen on validation AP for B = ``base_size``), ``real`` (real, that ratio, B) and
    ``more_real`` (targeted, 0, the largest of ``base_sizes`` above B: the most real shapes, the cell's
    positive control, as the AP experiment's ``real_data``) when their networks exist for every
    training seed, ``antipodal`` (None, None, None: a random antipodal grasp, the floor) and :data:`ORACLE` (None,
    None, None: the best grasp on the true mesh in the pose it rests in, :class:`graspaug.sim.oracle.MeshOracle`,
    the ceiling). ``seed_dirs``: training seed → the folder of its networks; a missing ``before`` or ``after``
    network is a :class:`DataError`."""
    best = float(best_ratio)
    chosen: dict[str, ArmNetwork] = {"before": ("targeted", 0.0, base_size), "after": ("targeted", best, base_size)}
    for seed_dir in seed_dirs.values():
        for pool, ratio, b in chosen.values():
            if not model_path(seed_dir, b, ratio, pool).exists():
                raise DataError(f"{model_path(seed_dir, b, ratio, pool)} is missing: run `dvc repro train_gqcnn` first")
    optional = {"real": ("real", best, base_size)} if best > 0 else {}
    larger = [b for b in base_sizes if b > base_size]
    if larger:
        optional["more_real"] = ("targeted", 0.0, max(larger))
    for arm, (pool, ratio, b) in optional.items():
        if all(model_path(seed_dir, b, ratio, pool).exists() for seed_dir in seed_dirs.values()):
            chosen[arm] = (pool, ratio, b)
        else:
            log.info("sim: no %s network at B = %d, ratio %g for every training seed: no %s arm", pool, b, ratio, arm)
    chosen["antipodal"] = chosen[ORACLE] = (None, None, None)
    return chosen


def after_ratio(ap_metrics: dict, base_size: int, ratios) -> tuple[float, bool]:
    """The ``after`` arm's ratio for ``base_size`` and whether it came from the AP report: the ratio
    chosen on validation AP in the report's metrics ``ap_metrics`` (``summary`` → base size →
    ``best_ratio``), else the largest of ``ratios`` (the ``generate.ratios``)."""
    summary = ap_metrics.get("summary", {}).get(str(base_size))
    best = float(max(ratios)) if summary is None else float(summary["best_ratio"])
    return best, summary is not None


def user_meshes(folder: str | Path | None, ingest) -> tuple[list[tuple[str, object]], dict[str, str]]:
    """The user's meshes (name, trimesh) of the folder ``sim.objects_path`` (none when it is None), prepared
    as the corpus's shapes with the ``ingest`` params' surface and size limits, and the files skipped
    (file name → why). An empty or unreadable folder is a :class:`DataError` (one line)."""
    if folder is None:
        return [], {}
    from graspaug.sim.objects import folder_meshes

    try:
        return folder_meshes(Path(folder), ingest.surface, ingest.max_faces, ingest.max_file_mb)
    except ValueError as exc:  # an empty or unreadable folder: one line, not a traceback
        raise DataError(str(exc)) from None


def test_shape_ids(shapes: pd.DataFrame, n: int, seed: int) -> list[str]:
    """The held-out shapes picked in the trials: a seeded choice of ``n`` from the test split of ``shapes``."""
    if n == 0:
        return []
    test = sorted(shapes.shape_id[shapes.split == "test"])
    if len(test) < n:
        raise DataError(f"sim.n_test_objects = {n} but the test split has {len(test)} shapes")
    chosen = shape_rng(seed, "sim", "test-objects").choice(len(test), size=n, replace=False)
    return [test[i] for i in sorted(chosen)]


def trial_objects(
    sim, shapes: pd.DataFrame, shapes_dir: Path, ingest, seed: int, workers=1
) -> tuple[list[PreparedObject], dict[str, str]]:
    """Every object of the trials of the ``sim`` params section (:func:`prepare_objects`): the everyday
    objects of ``sim.objects``, ``sim.n_test_objects`` test shapes of the table ``shapes``
    (:func:`test_shape_ids`; meshes in ``shapes_dir``) and the meshes of ``sim.objects_path``
    (:func:`user_meshes` with the ``ingest`` params), with the global ``seed`` and ``workers``; and
    the user's files skipped (file name → why)."""
    test_shapes = test_shape_ids(shapes, sim.n_test_objects, seed)
    user, skipped = user_meshes(sim.objects_path, ingest)
    objects = prepare_objects(
        sim.objects, test_shapes, shapes_dir, sim.physics, seed, sim.vhacd_resolution, user, workers=workers
    )
    return objects, skipped


def object_feasibility(objects: Sequence[PreparedObject], max_width: float) -> dict[str, dict]:
    """Each object's :func:`~graspaug.sim.feasibility.feasibility` for a jaw opening ``max_width`` m (object name →
    ``share``, ``feasible``, ``poses``, ``round``), judged from geometry alone on the mesh the cell shows (its body's
    visual mesh, m): no pick's outcome enters it."""
    import trimesh

    from graspaug.sim.feasibility import feasibility

    return {o.name: feasibility(trimesh.load(o.body.visual, force="mesh", process=False), max_width) for o in objects}


def object_jobs(
    objects: Sequence[PreparedObject],
    chosen: dict[str, ArmNetwork],
    seed_dirs: Mapping[int, Path],
    attempts: int,
    seed: int,
    n_pictures: int,
) -> list[ObjectJob]:
    """A job per object, arm and training seed (``seed_dirs``: training seed → the folder of its
    networks; the arms without a network, antipodal and oracle, once per object); the drops and planner seeds of an
    object are drawn from the global ``seed`` and its name, the same in every arm. The oracle's attempts are not
    recorded: it sees no depth image to draw."""
    model_seeds = list(seed_dirs)
    jobs = []
    for index, obj in enumerate(objects):
        drops = tuple(int(shape_rng(seed, obj.name, f"sim-drop-{a}").integers(2**31 - 1)) for a in range(attempts))
        plans = tuple(int(shape_rng(seed, obj.name, f"sim-plan-{a}").integers(2**31 - 1)) for a in range(attempts))
        record = index < n_pictures
        for arm, (pool, ratio, base_size) in chosen.items():
            if pool is None:
                shown = record and arm != ORACLE
                jobs.append(ObjectJob(arm, -1, None, obj.name, obj.kind, obj.body, drops, plans, shown))
                continue
            for s in model_seeds:
                jobs.append(
                    ObjectJob(
                        arm,
                        s,
                        str(model_path(seed_dirs[s], base_size, ratio, pool)),
                        obj.name,
                        obj.kind,
                        obj.body,
                        drops,
                        plans,
                        record and s == model_seeds[0],
                    )
                )
    return jobs


def _policy(model: str | None, layout, sampler, cem, crop_size: int, out_size: int):
    """The planner for ``model``, loaded once per worker process and file version."""
    if model is None:
        return _cached_policy(None, None, layout, sampler, cem, crop_size, out_size)
    path = os.path.abspath(model)
    stat = os.stat(path)
    return _cached_policy(path, (stat.st_mtime_ns, stat.st_size), layout, sampler, cem, crop_size, out_size)


@functools.lru_cache(maxsize=8)
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


def run_object(
    job: ObjectJob,
    layout,
    hand,
    sampler,
    cem,
    crop_size: int,
    out_size: int,
    trial_settings=None,
    sensor=None,
    gripper=None,
    grasps=None,
) -> list[dict]:
    """Every attempt of one object in one arm: a row per attempt (plus depth and frames for the
    first attempt when ``job.record``). The planner fills the sensor's missing pixels from the
    nearest valid one. ``gripper``: the hand's geometry (``grasps.gripper``; None: the default Franka hand). The
    :data:`ORACLE` arm plans no image: its grasps are the mesh oracle's (the ``grasps`` settings' sampler, quality
    and perturbations, with ``gripper``), seeded by the job's first planner seed; ``oracle_eps`` and
    ``oracle_tilt`` (rad) give its chosen grasp's robust ε and the jaw's tilt out of level."""
    import dataclasses

    from graspaug.grasping.gripper import ParallelJawGripper
    from graspaug.grasping.settings import GraspsSettings
    from graspaug.planning import check_depth
    from graspaug.sim.settings import DepthNoise
    from graspaug.sim.trials import TrialSettings, contacts_text, run_trial

    trial_settings, sensor = trial_settings or TrialSettings(), sensor or DepthNoise()
    gripper = gripper or ParallelJawGripper()
    oracle = None
    if job.arm == ORACLE:
        import trimesh

        from graspaug.sim.oracle import MeshOracle

        settings = dataclasses.replace(grasps or GraspsSettings(), gripper=gripper)
        mesh = trimesh.load(job.sim_object.visual, force="mesh", process=False)
        approach = trial_settings.pregrasp_height
        oracle = MeshOracle(mesh, settings, np.random.default_rng(job.plan_seeds[0]), approach_distance=approach)
    policy = None if oracle is not None else _policy(job.model, layout, sampler, cem, crop_size, out_size)
    rows = []
    for attempt, (drop_seed, plan_seed) in enumerate(zip(job.drop_seeds, job.plan_seeds)):
        rng = np.random.default_rng(plan_seed)
        record = job.record and attempt == 0
        scores: dict[str, float | None] = {arm: None for arm, _ in job.scorers}

        def plan(depth, camera, k, rng=rng, scores=scores):
            depth = check_depth(depth, fill_missing=True)  # filled once: the planner and every scorer see it
            planned = next(iter(policy.plan(depth, k, rng, camera_distance=camera.height)), None)
            for arm, path in job.scorers if planned is not None else ():
                scorer = _policy(path, layout, sampler, cem, crop_size, out_size)
                scores[arm] = float(scorer.score(depth, k, planned.grasp, camera.height)[0])
            return planned

        result = run_trial(
            job.sim_object,
            drop_seed,
            planner=None if oracle is not None else plan,
            scripted=oracle,
            layout=layout,
            hand=hand,
            settings=trial_settings,
            sensor=sensor,
            record=record,
            gripper=gripper,
            placement=job.placement,
        )
        g = result.image_grasp or {}
        center = result.grasp_center
        rows.append(
            {
                "arm": job.arm,
                "seed": job.seed,
                "object": job.name,
                "kind": job.kind,
                "attempt": attempt,
                "drop_seed": drop_seed,
                "outcome": result.outcome,
                "success": result.success,
                "quality": result.quality,
                "candidates": result.candidates,
                "u": g.get("u"),
                "v": g.get("v"),
                "angle": g.get("angle"),
                "depth": g.get("depth"),
                "width_px": g.get("width_px"),
                "grasp_x": None if center is None else center[0],
                "grasp_y": None if center is None else center[1],
                "grasp_z": None if center is None else center[2],
                "jaw_angle": result.jaw_angle,
                "contact_force": round(result.contact_force, 3),
                "contacts": contacts_text(result.contacts),
                "shake_grip": result.shake_grip,
                "mass": job.sim_object.mass,
                "planning_time": result.planning_time,
                **(
                    {
                        "oracle_eps": (oracle.chosen or {}).get("quality"),
                        "oracle_tilt": (oracle.chosen or {}).get("tilt"),
                    }
                    if oracle is not None
                    else {}
                ),
                "_depth": result.depth,
                "_frames": result.frames,
                **{f"score_{arm}": q for arm, q in scores.items()},
            }
        )
    return rows


def trials_plan(
    objects: Sequence,
    chosen: dict,
    attempts: int,
    n_seeds: int,
    skipped: dict[str, str],
    feasible: Mapping | None = None,
) -> str:
    """One line on what :func:`run_trials` will run: objects × attempts, the arms (``chosen``: arm →
    (pool, ratio, base size)) × training seeds, the ``after`` ratio, the count of skipped user meshes and, with
    ``feasible`` (:func:`object_feasibility`), of the feasible objects."""
    line = "%d objects × %d attempts; arms %s × %d training seeds (after = ratio %g); %d skipped meshes" % (
        len(objects),
        attempts,
        ", ".join(chosen),
        n_seeds,
        chosen["after"][1],
        len(skipped),
    )
    return line + (f"; {sum(f['feasible'] for f in feasible.values())} feasible objects" if feasible else "")


def run_trials(jobs: Sequence[ObjectJob], sim, crop, workers, gripper=None, grasps=None) -> list[dict]:
    """Every attempt of every job (:func:`run_object` on ``workers``, a process count or
    :class:`graspaug.parallel.Workers`): the rows of the jobs in order, one per attempt. ``sim``: the
    ``sim`` params section (cell, hand, sampler, CEM, trial settings, sensor); ``crop``: the render
    params' crop (``crop_size``, ``out_size`` px); ``gripper``: ``grasps.gripper``, the hand that picks; ``grasps``:
    the ``grasps`` settings the oracle arm samples and ranks its grasps with."""
    from graspaug.parallel import parallel_map

    work = functools.partial(
        run_object,
        layout=sim.cell,
        hand=sim.hand,
        sampler=sim.sampler,
        cem=sim.cem,
        crop_size=crop.crop_size,
        out_size=crop.out_size,
        trial_settings=sim.trial,
        sensor=sim.sensor,
        gripper=gripper,
        grasps=grasps,
    )
    return [row for rows in parallel_map(work, jobs, workers, "sim") for row in rows]


def trials_table(
    rows: list[dict], chosen: dict[str, ArmNetwork], feasible: Mapping[str, dict] | None = None
) -> pd.DataFrame:
    """The trials table: a row per attempt (:func:`run_object`'s rows without the pictures) and
    the ``ratio`` of its arm (``chosen``: arm → (pool, ratio, base size)); with ``feasible`` (object name → its
    :func:`object_feasibility`), each attempt's object's ``feasible`` and ``feasible_share``."""
    trials = pd.DataFrame([{k: v for k, v in row.items() if not k.startswith("_")} for row in rows])
    trials["ratio"] = trials.arm.map({arm: network[1] for arm, network in chosen.items()})
    if feasible is not None:
        trials["feasible"] = trials.object.map({name: bool(f["feasible"]) for name, f in feasible.items()})
        trials["feasible_share"] = trials.object.map({name: float(f["share"]) for name, f in feasible.items()})
    return trials
