"""Stage ``grasps``: antipodal grasps on every shape of a corpus, labelled by robust Ferrari-Canny.

``dvc.yaml`` runs it once per corpus (``grasps@original``; generated shapes get their own).
Outputs: ``data/grasps/<corpus>.parquet``, one row per grasp: ``shape_id``, ``grasp_id``,
``center_{x,y,z}``, ``axis_{x,y,z}`` (unit, jaw 1 → jaw 2), contacts ``p1_*``, ``p2_*`` with
outward normals ``n1_*``, ``n2_*`` (m, in the shape's normalized frame), ``width`` (m),
``eps`` (ε of the grasp as sampled), ``eps_mean`` / ``eps_std`` (robust ε over perturbations),
``success`` (``eps_mean > threshold``); and ``metrics/grasps/<corpus>.json``.
"""

from __future__ import annotations

import logging
import time
from pathlib import Path

import numpy as np
import pandas as pd

from graspaug.grasping.antipodal import sample_antipodal_grasps
from graspaug.grasping.robust import grasp_epsilon, robust_ferrari_canny
from graspaug.io.meshes import mesh_path, read_mesh
from graspaug.io.tables import read_table, write_json, write_table
from graspaug.params.base import params_model
from graspaug.params.grasps import GraspsParams
from graspaug.paths import grasps_metrics, grasps_table, timing_file
from graspaug.rng import shape_rng
from graspaug.stages import corpus_paths

log = logging.getLogger(__name__)

Params = params_model("The params the `grasps` stage reads.", grasps=GraspsParams)

VECTORS = ("center", "axis", "p1", "n1", "p2", "n2")


def grasps_of_shape(path: Path, shape_id: str, cfg: GraspsParams, seed: int) -> tuple[pd.DataFrame, str | None]:
    """The grasp rows of one mesh file and, if it has none, why."""
    mesh = read_mesh(path)
    rng = shape_rng(seed, shape_id)
    hand, quality = cfg.gripper, cfg.quality
    grasps = sample_antipodal_grasps(mesh, hand, cfg.sampler, rng)
    eps = grasp_epsilon(mesh, grasps.center, grasps.axis, quality.friction_coef, hand, quality)
    eps_mean, eps_std = robust_ferrari_canny(mesh, grasps.center, grasps.axis, hand, quality, cfg.perturbations, rng)
    columns: dict[str, object] = {
        "shape_id": np.full(len(grasps), shape_id, dtype=object),
        "grasp_id": np.arange(len(grasps)),
    }
    for name in VECTORS:
        values = getattr(grasps, name)
        for i, axis in enumerate("xyz"):
            columns[f"{name}_{axis}"] = values[:, i]
    columns.update(width=grasps.width, eps=eps, eps_mean=eps_mean, eps_std=eps_std, success=eps_mean > cfg.threshold)
    reason = None
    if len(grasps) == 0:
        smallest = float(np.min(mesh.bounding_box_oriented.extents))
        reason = (
            f"its oriented bounding box's smallest side, {smallest:.3f} m, is wider than the {hand.max_width} m opening"
            if smallest >= hand.max_width
            else f"no antipodal grasp passed the width and force-closure tests in {cfg.sampler.max_rounds} rounds"
        )
    return pd.DataFrame(columns), reason


def run(params: Params, corpus: str = "original") -> None:
    from graspaug.parallel import parallel_map

    files = corpus_paths(corpus)
    start = time.perf_counter()
    cfg = params.grasps
    table_path, mesh_dir, suffix = files
    shape_ids = list(read_table(table_path)["shape_id"])
    jobs = [(mesh_path(mesh_dir.resolve(), s, suffix), s) for s in shape_ids]  # workers may have another cwd
    results = parallel_map(
        lambda job: grasps_of_shape(job[0], job[1], cfg, params.seed), jobs, params.workers, f"grasps ({corpus})"
    )
    for shape_id, (_, reason) in zip(shape_ids, results):
        if reason:
            log.warning("grasps: %s has no grasp: %s", shape_id, reason)
    table = pd.concat([rows for rows, _ in results], ignore_index=True)
    write_table(table, grasps_table(corpus))

    seconds = time.perf_counter() - start
    per_shape = table.groupby("shape_id").size().reindex(shape_ids, fill_value=0)
    summary = {
        "n_shapes": len(shape_ids),
        "n_grasps": int(len(table)),
        "shapes_without_grasps": int((per_shape == 0).sum()),
        "grasps_per_shape_mean": round(float(per_shape.mean()), 2),
        "success_share": round(float(table.success.mean()), 4) if len(table) else None,
        "eps_mean_median": round(float(table.eps_mean.median()), 6) if len(table) else None,
        "nominal_force_closure_share": round(float((table.eps > 0).mean()), 4) if len(table) else None,
    }
    write_json(summary, grasps_metrics(corpus))
    write_json({"seconds": round(seconds, 1)}, timing_file("grasps", corpus))
    log.info(
        "grasps (%s): %d grasps on %d shapes (%d without), %.1f%% successful, in %.1f s",
        corpus,
        len(table),
        len(shape_ids),
        summary["shapes_without_grasps"],
        100 * (summary["success_share"] or 0),
        seconds,
    )
