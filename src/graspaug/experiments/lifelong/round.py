"""One round of the lifelong loop: grasp and render the round's new shapes, score the round's networks, write its
files."""

from __future__ import annotations

import logging
from pathlib import Path

import numpy as np
import pandas as pd

from graspaug.experiments.lifelong.figures import curve_series
from graspaug.experiments.lifelong.numbers import (
    ARMS,
    arm_contrasts,
    curve_rows,
    failure_history,
    followed_failures,
    persistent_failures,
    validation_errors,
)
from graspaug.experiments.lifelong.words import round_markdown
from graspaug.experiments.stats import (
    draw_scope,
    headline,
    share_headline,
)
from graspaug.grasping.labelled import grasps_of_shapes
from graspaug.io.atomic import atomic_path
from graspaug.io.gqcnn import append_grasp_images
from graspaug.io.meshes import mesh_path, write_obj
from graspaug.io.tables import write_json_files
from graspaug.plots import lines, voxel_rows
from graspaug.render.corpus_dataset import datapoints_table, render_corpus, with_pool_columns
from graspaug.render.dataset import SHAPE_COLUMNS, datapoints_index

log = logging.getLogger(__name__)


PICTURED = 8  # objects in the picture of persistent failures


def grasp_and_render(
    shapes: pd.DataFrame, mesh_dir: Path, suffix: str, grasps, settings, seed: int, workers: int, label
) -> tuple[np.ndarray, pd.DataFrame, pd.DataFrame, list[dict]]:
    """What ``grasps`` then ``render`` make of a few new shapes at once (the lifelong loop's rounds).

    Parameters
    ----------
    shapes : the shapes' table: ``shape_id`` and the other columns of
        :data:`graspaug.render.dataset.SHAPE_COLUMNS` (missing ones are added empty)
    mesh_dir, suffix : their mesh files (m, :func:`graspaug.io.meshes.mesh_path`)
    grasps : the ``grasps`` params (gripper, sampler, wrench model, perturbations, threshold)
    settings, seed, workers, label : as :func:`graspaug.render.corpus_dataset.render_corpus` takes them

    Returns
    -------
    (images (N, out, out) float32, index (N rows, :func:`~graspaug.render.corpus_dataset.datapoints_table`),
    grasp table, the shapes without a datapoint with their reasons)
    """
    shapes = with_pool_columns(shapes.copy())
    table, reasons = grasps_of_shapes(
        mesh_dir, list(shapes.shape_id), suffix, grasps, seed, workers, f"grasps ({label})"
    )
    for shape_id, reason in reasons.items():
        log.warning("%s: %s has no grasp: %s", label, shape_id, reason)
    hand = grasps.gripper
    by_shape, results = render_corpus(shapes, table, Path(mesh_dir), suffix, settings, hand, seed, workers, label)
    images, parts, skipped, _, _ = datapoints_index(shapes, by_shape, results, grasps.threshold)
    if not parts:  # no new datapoint: an empty index with the columns a dataset's has
        empty = pd.DataFrame(columns=[*SHAPE_COLUMNS, "z", "label", "eps"])
        return np.zeros((0, settings.crop.out_size, settings.crop.out_size), np.float32), empty, table, skipped
    return np.concatenate(images), datapoints_table(parts), table, skipped


def render_round(meshes: Path, dataset: Path, previous: Path | None, index, kept, grasps, render, seed, workers, label):
    """Write a round's new shapes (``index``: :func:`graspaug.augment.failures.loop_shapes`, ``kept`` its decodes)
    into the empty folder ``meshes`` (``<shape_id>.obj``, m), label their grasps and render their crops as ``grasps``
    and ``render`` do (params sections; ``seed``, ``workers``, ``label``), and write into the empty folder
    ``dataset`` the datapoints of ``previous`` (the last round's dataset; None in round 1) followed by the new ones.
    Returns (datapoints in all, the new shapes without a datapoint with their reasons)."""
    for shape_id, decoded in zip(index.shape_id, kept):
        write_obj(decoded.mesh, mesh_path(meshes, shape_id, ".obj"))
    images, rows, _, skipped = grasp_and_render(index, meshes, ".obj", grasps, render, seed, workers, label)
    for arm, shapes in index.groupby("arm").shape_id:
        gave = rows.shape_id[rows.shape_id.isin(shapes)].nunique()
        log.info("%s: %d of %d new %s shapes gave datapoints", label, gave, len(shapes), arm)
    return append_grasp_images(dataset, previous, images, rows, render.shard_rows), skipped


def score_round(seed_dirs, variants, arms, corpus, before: pd.DataFrame, history: pd.DataFrame, round_: int, worst):
    """The round's arms on the validation objects: (the failure arm's :func:`validation_errors` with ``chosen``
    marking its ``worst`` objects, the next round's failures; ``history`` with them appended; the last round's
    chosen objects in ``before`` (its failures table) before and under each arm now, :func:`followed_failures`).
    ``seed_dirs``: training seed → folder of the round's networks; ``variants``: the arms' (in ``arms`` order);
    ``corpus``: the original corpus's index."""
    after = {arm: validation_errors(seed_dirs, v.name, corpus)[0] for arm, v in zip(arms, variants)}
    failing = after["failure"]
    chosen = list(failing.index[:worst])
    followed = followed_failures(before, after, list(before.index[before.chosen]))
    return failing.assign(chosen=failing.index.isin(chosen)), failure_history(history, round_, chosen), followed


def write_round(
    round_: int,
    networks: dict,
    labels,
    objects,
    curve: pd.DataFrame | None,
    history: pd.DataFrame,
    params,
    voxels,
    metrics_dir: Path,
    report_dir: Path,
    followed: pd.DataFrame | None = None,
    header: str = "",
) -> pd.DataFrame:
    """Round ``round_``'s figures (:func:`~graspaug.experiments.lifelong.numbers.arm_contrasts` of ``networks``: draw
    → seed → arm → folder, tested on ``labels`` / ``objects`` (N,)) as metrics files in ``metrics_dir`` and its
    report, curve and failures picture (``history``: the failures chosen so far; ``voxels``: the corpus's VoxelSet;
    ``followed``: the last round's failures before and now, None in round 0; ``header``: the lines report.md opens with,
    the profile and corpus that made it) in ``report_dir``; ``params`` the
    stage's (``lifelong``, ``gqcnn.seeds``, ``seed``, ``data_seed``). Returns ``curve`` (None in round 0) with this
    round's rows appended."""
    cfg = params.lifelong
    result = arm_contrasts(networks, labels, objects, cfg.n_bootstrap, params.seed)
    figures = {f"ap_{arm}": headline(ap) for arm, ap in result["ap"].items()}
    figures |= {name: headline(c) for name, c in result["contrasts"].items()}
    figures |= {"share": share_headline(result["share"])} if "share" in result else {}
    write_json_files(figures, metrics_dir)
    curve = curve_rows(round_, result) if curve is None else pd.concat([curve, curve_rows(round_, result)])
    persistent = persistent_failures(history)
    design = (
        f"Base set B = {cfg.base_size}; each arm adds {cfg.shapes_per_round} shapes per round (round {round_}: "
        f"{round_ * cfg.shapes_per_round}); failures: the {cfg.worst} worst validation objects, {cfg.per_failure} "
        "anchors each. Intervals: 95%, over the seeds (t) and the test objects (bootstrap), in quadrature. "
        f"{draw_scope(params.data_seed, params.gqcnn.seeds, 'lifelong')}"
    )
    words = {"design": design, "command": f"dvc repro lifelong@r{round_}" if round_ else "dvc repro lifelong_start"}
    with atomic_path(report_dir, directory=True) as folder:
        (folder / "report.md").write_text(header + round_markdown(round_, result, followed, persistent, words))
        rounds, series, bands = curve_series(curve, ARMS if round_ else ["none"])
        title = f"Test AP per round (B = {cfg.base_size}, 95% intervals over seeds × test objects)"
        lines(rounds, series, folder / "curve.png", "round", "test AP", title, bands)
        rounds, series, bands = curve_series(curve, ARMS, "gain")
        title = f"Gain over round 0, paired within seeds (B = {cfg.base_size}, 95% intervals)"
        lines(rounds, series, folder / "gain.png", "round", "test AP − round 0's", title, bands)
        at = {s: i for i, s in enumerate(voxels.shape_id)}
        shown = persistent.head(PICTURED)
        cells = [(voxels.occupancy[at[o]], voxels.occupancy[at[o]]) for o in shown.object]
        names = [f"{o} ({n} rounds)" for o, n in zip(shown.object, shown.rounds)]
        voxel_rows(
            [cells], [f"up to r{round_}"], names, folder / "failures.png", "Validation objects chosen most often"
        )
        if followed is not None:
            followed.to_csv(folder / "followed.csv")
    return curve
