"""Grasp calibration: does the cell hold what the labels call graspable? Executes chosen grasps with the Panda,
summarizes success per label and the ROC AUC of ε and the label against the outcomes, and draws them
(``calibration.png``: its data :func:`success_by_eps`, its drawing :func:`label_calibration`, its caption
:func:`draw_label_calibration`)."""

from __future__ import annotations

import functools
import os
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import pandas as pd
from scipy.spatial.transform import Rotation

from graspaug.experiments.stats import (
    ObjectBootstrap,
    percentile_interval,
    wilson_interval,
)
from graspaug.plots import pyplot, save_figure
from graspaug.rng import shape_rng
from graspaug.sim.objects import prepare_objects

#: Columns of the rendered dataset's index that a calibration row keeps (``datapoint``: the row in the index).
INDEX_COLUMNS = (
    "datapoint",
    "shape_id",
    "grasp_id",
    "pose_id",
    "pose_probability",
    "eps",
    "collision_free",
    "success",
    "label",
)


def choose_grasps(index: pd.DataFrame, n: int, seed: int, split: str = "test") -> pd.DataFrame:
    """``n`` datapoints of the ``split`` of the rendered dataset's ``index`` (one row per
    datapoint: ``shape_id``, ``split``, ``label``, …; the result's ``datapoint`` is the row
    there), half labelled positive and half negative (negatives fill in for missing positives;
    fewer than ``n`` only when the split has fewer),
    spread over as many shapes as possible: within a label, every shape gives its first (seeded
    random) datapoint before any gives a second. Sorted by shape. Raises ValueError when the
    split is empty. (Settings of the cell are tuned on the train split, measured on test.)"""
    candidates = index.assign(datapoint=np.arange(len(index)))[index.split.to_numpy() == split]
    if candidates.empty:
        raise ValueError(f"the rendered dataset has no {split}-split datapoints to execute")
    rng = shape_rng(seed, "sim", "grasp-calibration")
    positives = min(n - n // 2, int(candidates.label.sum()))
    chosen = []
    for label, want in ((True, positives), (False, n - positives)):
        rows = candidates[candidates.label == label]
        rows = rows.iloc[rng.permutation(len(rows))]
        rank = rows.groupby("shape_id").cumcount()
        chosen.append(rows.assign(_rank=rank.to_numpy()).sort_values("_rank", kind="stable").head(want))
    out = pd.concat(chosen).drop(columns="_rank")
    return out.sort_values(["shape_id", "pose_id", "grasp_id"], kind="stable").reset_index(drop=True)


@dataclass(frozen=True)
class ShapeGrasps:
    """One shape's G grasps to execute: ``poses`` (G, 4, 4), each putting the shape's mesh (own
    frame) at rest on the table z = 0 in that grasp's stable pose; ``centers`` / ``axes`` (G, 3)
    are the grasps in the mesh's frame; ``rows`` the datapoints' index rows."""

    shape_id: str
    sim_object: object  # graspaug.sim.objects.SimObject
    origin: np.ndarray  # (3,) the body origin in the mesh frame (graspaug.sim.objects.body_origin)
    poses: np.ndarray
    centers: np.ndarray
    axes: np.ndarray
    rows: pd.DataFrame
    trial_seeds: tuple[int, ...]


def placement(pose: np.ndarray, origin: np.ndarray, clearance: float = 0.001) -> tuple[np.ndarray, np.ndarray]:
    """Body position (3,) m and quaternion (x, y, z, w) that put a mesh at ``pose`` (4, 4) on the
    table, lifted by ``clearance`` m; ``origin`` (3,): the body's origin in the mesh frame."""
    position = pose[:3, :3] @ origin + pose[:3, 3] + [0.0, 0.0, clearance]
    return position, Rotation.from_matrix(pose[:3, :3]).as_quat()


def grasp_on_body(center: np.ndarray, axis: np.ndarray, origin: np.ndarray, position, quaternion):
    """A grasp given in the mesh frame (``center``, unit ``axis`` (3,)) on the body resting at
    ``position`` (3,) m and ``quaternion`` (x, y, z, w): table-frame center (3,) m, jaw angle
    in the table plane from the x axis (rad) and the axis's tilt out of the table plane (deg)."""
    rotation = Rotation.from_quat(quaternion)
    table_center = rotation.apply(np.asarray(center) - origin) + np.asarray(position)
    a = rotation.apply(np.array(axis, dtype=float))
    return table_center, float(np.arctan2(a[1], a[0])), float(np.degrees(np.arcsin(min(1.0, abs(a[2])))))


def run_shape(job: ShapeGrasps, layout, hand, trial_settings, gripper=None) -> list[dict]:
    """Every grasp of one shape executed in a fresh cell (:func:`graspaug.sim.trials.run_trial`
    with the object placed in the grasp's stable pose): one row per grasp, the index row plus
    ``outcome``, ``executed_success``, the object's drift while settling (``settle_shift`` m),
    the jaw axis's tilt out of the table at the grasp (``axis_tilt`` deg), the grasp center's
    height above the table (``grasp_height`` m) and ``contact_force``
    (N, the robot's largest contact before the fingers closed). ``gripper``: the hand's geometry (``grasps.gripper``;
    None: the default Franka hand)."""
    from graspaug.grasping.gripper import ParallelJawGripper
    from graspaug.sim.trials import contacts_text, run_trial

    gripper = gripper or ParallelJawGripper()

    rows = []
    for pose, center, axis, row, trial_seed in zip(
        job.poses, job.centers, job.axes, job.rows.to_dict("records"), job.trial_seeds
    ):
        start = placement(pose, job.origin)
        seen: dict[str, float] = {}

        def scripted(position, quaternion, center=center, axis=axis, start=start, seen=seen):
            table_center, jaw_angle, tilt = grasp_on_body(center, axis, job.origin, position, quaternion)
            seen["shift"], seen["tilt"], seen["height"] = (
                float(np.linalg.norm(position - start[0])),
                tilt,
                table_center[2],
            )
            return table_center, jaw_angle

        result = run_trial(
            job.sim_object,
            trial_seed,
            scripted=scripted,
            layout=layout,
            hand=hand,
            settings=trial_settings,
            placement=start,
            gripper=gripper,
        )
        rows.append(
            {
                **{k: row[k] for k in INDEX_COLUMNS},
                "outcome": result.outcome,
                "executed_success": result.success,
                "settle_shift": seen["shift"],
                "axis_tilt": seen["tilt"],
                "grasp_height": float(seen["height"]),
                "contact_force": round(result.contact_force, 3),
                "contacts": contacts_text(result.contacts),
            }
        )
    return rows


def shape_jobs(chosen: pd.DataFrame, grasps: pd.DataFrame, shapes_dir, sim, seed: int, workers=1) -> list[ShapeGrasps]:
    """A job per shape of ``chosen`` (:func:`choose_grasps`): ``grasps`` the grasps table
    (``grasp_id``, ``center_*``, ``axis_*`` per shape, mesh frame); the meshes are read from the
    folder ``shapes_dir`` and made into bodies as the ``sim`` stage makes them (``sim``: the
    ``sim`` params section; decompositions on ``workers``); trial seeds from the global ``seed``,
    the shape and the datapoint. Stable poses are recomputed from the mesh, as the render stage
    numbered them."""
    from graspaug.io.meshes import mesh_path, read_mesh
    from graspaug.render.stable_poses import stable_poses
    from graspaug.sim.objects import body_origin

    ids = sorted(chosen.shape_id.unique())
    meshes = {shape_id: read_mesh(mesh_path(shapes_dir, shape_id)) for shape_id in ids}
    prepared = prepare_objects((), ids, shapes_dir, sim.physics, seed, sim.vhacd_resolution, workers=workers)
    objects = {o.name: o.body for o in prepared}
    by_id = grasps.set_index(["shape_id", "grasp_id"])
    jobs = []
    for shape_id, rows in chosen.groupby("shape_id", sort=True):
        mesh = meshes[shape_id]
        g = by_id.loc[[(shape_id, i) for i in rows.grasp_id]]
        jobs.append(
            ShapeGrasps(
                shape_id,
                objects[shape_id],
                body_origin(mesh),
                stable_poses(mesh).transforms[rows.pose_id.to_numpy()],
                g[["center_x", "center_y", "center_z"]].to_numpy(float),
                g[["axis_x", "axis_y", "axis_z"]].to_numpy(float),
                rows.reset_index(drop=True),
                tuple(
                    int(shape_rng(seed, shape_id, f"calibration-{p}-{g}").integers(2**31 - 1))
                    for p, g in zip(rows.pose_id, rows.grasp_id)
                ),
            )
        )
    return jobs


def run_calibration(jobs: Sequence[ShapeGrasps], sim, workers, gripper=None) -> pd.DataFrame:
    """Every job's grasps (:func:`run_shape` on ``workers``), one row per executed grasp;
    ``sim``: the ``sim`` params section (cell, hand, trial settings); ``gripper``: ``grasps.gripper`` (the hand)."""
    from graspaug.parallel import parallel_map

    work = functools.partial(run_shape, layout=sim.cell, hand=sim.hand, trial_settings=sim.trial, gripper=gripper)
    return pd.DataFrame([row for rows in parallel_map(work, jobs, workers, "grasp calibration") for row in rows])


def summarize(table: pd.DataFrame, n_bootstrap: int, seed: int) -> dict:
    """Success per label and how well the labels rank outcomes, over the executed grasps of
    ``table`` (:func:`run_calibration`): success rate of the grasps labelled positive and
    negative; ROC AUC of the robust ε over all grasps (``auc_eps``) and over those labelled
    collision-free (``auc_eps_collision_free``), of the label's continuous form, ε where the
    approach is collision-free and 0 where not (``auc_quality``), and of the label itself.
    Intervals: percentile bootstrap over shapes (``n_bootstrap`` resamples; grasps of one shape
    share its physics and mesh); None where one outcome is missing."""
    from sklearn.metrics import roc_auc_score

    y = table.executed_success.to_numpy(bool)
    boot = ObjectBootstrap(table.shape_id.to_numpy(), n_bootstrap, shape_rng(seed, "sim", "calibration-bootstrap"))
    members = [np.flatnonzero(boot.object_index == k) for k in range(boot.object_counts.shape[1])]
    resamples = [np.concatenate([members[k] for k in draw]) for draw in boot.draws]

    def resampled(statistic) -> dict:
        """The statistic on every grasp and its interval; None where one outcome or label is missing."""
        value = statistic(np.arange(len(table)))
        if not np.isfinite(value):
            return {"mean": None, "lo": None, "hi": None}
        samples = np.array([statistic(idx) for idx in resamples])
        lo, hi = percentile_interval(samples[np.isfinite(samples)])
        return {"mean": value, "lo": lo, "hi": hi}

    def auc(score: np.ndarray, mask: np.ndarray | None = None):
        def statistic(idx):
            idx = idx if mask is None else idx[mask[idx]]
            if len(np.unique(y[idx])) < 2:
                return np.nan
            return float(roc_auc_score(y[idx], score[idx]))

        return statistic

    def rate(mask: np.ndarray):
        def statistic(idx):
            idx = idx[mask[idx]]
            return float(y[idx].mean()) if len(idx) else np.nan

        return statistic

    label = table.label.to_numpy(bool)
    free = table.collision_free.to_numpy(bool)
    eps = table.eps.to_numpy(float)
    outcomes = table.groupby("label").outcome.value_counts().unstack(fill_value=0)
    return {
        "n_grasps": int(len(table)),
        "n_shapes": int(table.shape_id.nunique()),
        "n_positive": int(label.sum()),
        "success_positive": resampled(rate(label)),
        "success_negative": resampled(rate(~label)),
        "auc_eps": resampled(auc(eps)),
        "auc_eps_collision_free": resampled(auc(eps, free)),
        "auc_quality": resampled(auc(np.where(free, eps, 0.0))),
        "auc_label": resampled(auc(label.astype(float))),
        "outcomes": {("positive" if k else "negative"): v for k, v in outcomes.to_dict("index").items()},
    }


def success_by_eps(table: pd.DataFrame, n_bins: int = 8) -> pd.DataFrame:
    """Executed success per robust-ε bin (quantile bins of all executed grasps' ε), apart for grasps
    labelled collision-free and colliding: ``collision_free``, ``eps_low``, ``eps_high`` (bin
    edges), ``eps_mid`` (median ε of the bin's grasps), ``grasps``, ``successes``, ``rate`` and its
    95% Wilson interval ``lo``, ``hi``."""

    edges = np.unique(np.quantile(table.eps, np.linspace(0, 1, n_bins + 1)))
    bins = np.clip(np.searchsorted(edges, table.eps, side="right") - 1, 0, len(edges) - 2)
    rows = []
    for (free, b), group in table.groupby([table.collision_free, bins]):
        n, k = len(group), int(group.executed_success.sum())
        lo, hi = wilson_interval(k, n)
        rows.append(
            {
                "collision_free": bool(free),
                "eps_low": edges[b],
                "eps_high": edges[b + 1],
                "eps_mid": float(group.eps.median()),
                "grasps": n,
                "successes": k,
                "rate": k / n,
                "lo": lo,
                "hi": hi,
            }
        )
    return pd.DataFrame(rows)


def label_calibration(by_eps: pd.DataFrame, grasps: pd.DataFrame, path: str | os.PathLike, title: str) -> None:
    """Do executed grasps follow their labels? Left: success rate per robust-ε bin (``by_eps``:
    ``collision_free``, ``eps_mid``, ``rate``, ``lo``, ``hi``), one line for grasps labelled
    collision-free and one for colliding ones. Right: ROC curves of
    the robust ε and of the label against the executed outcome (``grasps``: ``eps``, ``label``,
    ``executed_success``), AUC in the legend."""
    from sklearn.metrics import roc_auc_score, roc_curve

    plt = pyplot()
    fig, (rates, roc) = plt.subplots(1, 2, figsize=(11, 4.5))
    for free, group in by_eps.groupby("collision_free"):
        group = group.sort_values("eps_mid")
        rate = group.rate.to_numpy(float)
        rates.errorbar(
            group.eps_mid * 1000,
            rate,
            yerr=[rate - group.lo.to_numpy(float), group.hi.to_numpy(float) - rate],
            marker="o",
            capsize=3,
            label="labelled collision-free approach" if free else "labelled colliding approach",
        )
    rates.set_xlabel("robust ε (×1000), median of the bin")
    rates.set_ylabel("executed success rate (95% Wilson)")
    rates.set_ylim(0, 1.02)
    y = grasps.executed_success.to_numpy(bool)
    if 0 < y.sum() < len(y):
        for name, score in (("robust ε", grasps.eps), ("label", grasps.label.astype(float))):
            fpr, tpr, _ = roc_curve(y, score)
            roc.plot(fpr, tpr, label=f"{name} (AUC {roc_auc_score(y, score):.3f})")
    else:
        roc.text(0.5, 0.5, "one outcome only: no curve", ha="center", va="center")
    roc.plot([0, 1], [0, 1], color="gray", ls=":", label="chance")
    roc.set_xlabel("false positive rate")
    roc.set_ylabel("true positive rate")
    for ax in (rates, roc):
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle(title)
    save_figure(fig, path)


def draw_label_calibration(by_eps: pd.DataFrame, grasps: pd.DataFrame, path: str | os.PathLike) -> None:
    """``calibration.png``: :func:`label_calibration` of ``by_eps`` (:func:`success_by_eps`) and ``grasps`` (one row
    per executed grasp), titled with how many grasps were executed."""
    label_calibration(by_eps, grasps, path, f"{len(grasps)} labelled test grasps executed in the cell")


def calibration_headline(summary: dict) -> dict[str, dict]:
    """The metrics files: name → {mean, lo, hi} for the success rates per label and the ROC AUCs."""
    names = ("success_positive", "success_negative", "auc_eps", "auc_eps_collision_free", "auc_quality", "auc_label")
    return {name: {k: None if v is None else round(float(v), 5) for k, v in summary[name].items()} for name in names}


def summary_line(summary: dict) -> str:
    """One line of a :func:`summarize` result: success per label and the ROC AUCs of ε and of Dex-Net's score,
    each with its interval ("n/a" where one outcome is missing)."""

    def figure(name: str) -> str:
        f = summary[name]
        return "n/a" if f["mean"] is None else f"{f['mean']:.3f} [{f['lo']:.3f}, {f['hi']:.3f}]"

    return (
        f"{summary['n_grasps']} grasps on {summary['n_shapes']} shapes; success {figure('success_positive')} of "
        f"positives, {figure('success_negative')} of negatives; ROC AUC of robust eps {figure('auc_eps')}, of eps "
        f"with colliding grasps at 0 {figure('auc_quality')}"
    )
