"""The ``grasps`` stage's table: every shape's antipodal grasps labelled by robust Ferrari-Canny, and its summary."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from graspaug.grasping.antipodal import sample_antipodal_grasps
from graspaug.grasping.robust import grasp_epsilon, robust_ferrari_canny
from graspaug.grasping.settings import GraspsSettings
from graspaug.io.meshes import read_mesh
from graspaug.rng import shape_rng

VECTORS = ("center", "axis", "p1", "n1", "p2", "n2")


def grasps_of_shape(path: Path, shape_id: str, cfg: GraspsSettings, seed: int) -> tuple[pd.DataFrame, str | None]:
    """The grasp rows of one mesh file and, if it has none, why.

    Parameters
    ----------
    path : the shape's mesh file (m, in its normalized frame).
    shape_id : the shape's id; with ``seed`` it seeds the shape's own generator (:func:`graspaug.rng.shape_rng`).
    cfg : the ``grasps`` params: gripper, sampler, wrench model, perturbations, success threshold.

    Returns
    -------
    rows : one row per grasp (G rows): ``shape_id``, ``grasp_id`` (0 .. G − 1), ``<v>_{x,y,z}`` for ``v`` in
        :data:`VECTORS` (centre and contacts in m, unit axis and outward normals), ``width`` (m), ``eps``
        (ε as sampled), ``eps_mean`` / ``eps_std`` (robust ε over perturbations), ``success``
        (``eps_mean > cfg.threshold``).
    reason : None, or (G = 0) why the shape has no grasp, in words.
    """
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


def grasps_summary(table: pd.DataFrame, shape_ids: list[str]) -> dict[str, float | int | None]:
    """The grasps metrics of a corpus: its ``shape_ids`` (S,) and their grasp ``table`` (:func:`grasps_of_shape`
    rows). ``n_shapes``, ``n_grasps``, ``shapes_without_grasps``, ``grasps_per_shape_mean``, and (None without
    grasps) ``success_share`` and ``nominal_force_closure_share`` (0..1, the share with ε > 0 as sampled) and
    ``eps_mean_median`` (robust ε)."""
    per_shape = table.groupby("shape_id").size().reindex(shape_ids, fill_value=0)
    return {
        "n_shapes": len(shape_ids),
        "n_grasps": int(len(table)),
        "shapes_without_grasps": int((per_shape == 0).sum()),
        "grasps_per_shape_mean": round(float(per_shape.mean()), 2),
        "success_share": round(float(table.success.mean()), 4) if len(table) else None,
        "eps_mean_median": round(float(table.eps_mean.median()), 6) if len(table) else None,
        "nominal_force_closure_share": round(float((table.eps > 0).mean()), 4) if len(table) else None,
    }


def grasps_headline(summary: dict) -> dict[str, float | int | None]:
    """The stage's metrics from its :func:`grasps_summary`: ``shapes`` of the corpus and the share of
    grasps labelled positive (``positive``, robust ε above the threshold)."""
    return {"shapes": summary["n_shapes"], "positive": summary["success_share"]}


def grasps_of_shapes(
    mesh_dir: Path, shape_ids: list[str], suffix: str, cfg: GraspsSettings, seed: int, workers, label: str
) -> tuple[pd.DataFrame, dict[str, str]]:
    """:func:`grasps_of_shape` for every shape of ``shape_ids`` (meshes ``<mesh_dir>/<shape_id><suffix>``) on
    ``workers`` processes (progress ``label``): (every grasp row, in shape order; shape id → why it has no grasp, for
    the shapes without one)."""
    from graspaug.io.meshes import mesh_path
    from graspaug.parallel import parallel_map

    jobs = [(mesh_path(Path(mesh_dir).resolve(), s, suffix), s) for s in shape_ids]  # workers may have another cwd
    results = parallel_map(lambda job: grasps_of_shape(job[0], job[1], cfg, seed), jobs, workers, label)
    reasons = {shape_id: reason for shape_id, (_, reason) in zip(shape_ids, results) if reason}
    return pd.concat([rows for rows, _ in results], ignore_index=True), reasons
