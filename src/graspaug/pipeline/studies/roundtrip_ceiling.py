"""``graspaug study roundtrip-ceiling``: what could a perfect decoder hand over? Graspness kept when a shape goes
through a grid and back to a mesh.

For ``shapes`` random train shapes of a project (``seed`` picks them), each shape's grasps are labelled as
the ``grasps`` stage labels them (:func:`graspaug.grasping.labelled.grasps_of_shape`, the project's ``grasps``
params and ``seed``, the shape's own random stream) on

- ``original``: its ingested mesh;
- ``occupancy R``: its solid occupancy at R³ (fit_grid with ``voxelize.margin`` + voxelize_solid, as the
  ``voxelize`` stage makes it) meshed by :func:`graspaug.geometry.from_voxels.mesh_decoded` with the project's
  ``generate.decode`` settings, as if the grid were a perfect decode;
- ``tsdf R``: its exact truncated signed distance at R³ on the same grid
  (:func:`graspaug.geometry.sdf.truncated_distance_grid`, ``truncation`` voxels) meshed by
  :func:`graspaug.geometry.sdf.mesh_from_sdf` (marching cubes at 0, no opening, no smoothing; the same
  ``min_voxels`` and ``min_main_share`` rejections), centred on its centre of mass as a decode would be;

for R = 32 and 64. Each reconstruction is written as a generated shape is (OBJ) and read back before labelling.
Graspness is a shape's share of positive grasps (:func:`graspaug.augment.scores.graspness`; 0 without grasps).
Per row, over the shapes that meshed: graspness kept = mean after / mean before (Fieller 95% interval of the
ratio of paired means), the paired difference after − before with its 95% t-interval over shapes, and how
many meshed. Writes ``rows.csv``, ``per_shape.csv``, ``summary.json`` (the rows and the run's settings) and
``timing.json`` (seconds per shape of each grid and mesh step) into its output folder and returns the markdown
table it prints. Runs on a project where ``ingest`` has run (``data/shapes.parquet``, ``data/shapes/``).
"""

from __future__ import annotations

import dataclasses
import logging
import tempfile
import time
from pathlib import Path

import numpy as np
import pandas as pd

from graspaug.experiments.fidelity.numbers import mesh_graspness, paired_graspness_kept
from graspaug.experiments.fidelity.words import paired_graspness_kept_markdown
from graspaug.geometry.from_voxels import mesh_decoded
from graspaug.geometry.sdf import mesh_from_sdf, truncated_distance_grid
from graspaug.geometry.voxelize import fit_grid, voxelize_solid
from graspaug.io.meshes import mesh_path, read_mesh, write_obj
from graspaug.io.tables import read_table, write_csv, write_json
from graspaug.parallel import parallel_map
from graspaug.pipeline.params.model import load_params
from graspaug.pipeline.paths import GENERATED_SUFFIX, SHAPES_TABLE, corpus_files

log = logging.getLogger(__name__)

RESOLUTIONS = (32, 64)
VARIANTS = ("original", *(f"{recipe} {r}" for recipe in ("occupancy", "tsdf") for r in RESOLUTIONS))


def reconstructions(mesh, margin: int, decode, truncation: float) -> tuple[dict, dict]:
    """Every variant's mesh of ``mesh`` (or the reason it has none), and the seconds each step took."""
    meshes, seconds = {"original": (mesh, None)}, {}
    for resolution in RESOLUTIONS:
        grid = fit_grid(mesh.bounds, resolution, margin)
        start = time.perf_counter()
        occupancy = voxelize_solid(mesh.vertices, mesh.faces, grid)
        _, decoded, reason = mesh_decoded(occupancy.astype(np.float32), grid.pitch, decode)
        seconds[f"occupancy {resolution}"] = time.perf_counter() - start
        meshes[f"occupancy {resolution}"] = (decoded, reason)

        start = time.perf_counter()
        sdf = truncated_distance_grid(mesh.vertices, mesh.faces, grid, truncation)
        seconds[f"tsdf {resolution} field"] = time.perf_counter() - start
        start = time.perf_counter()
        surface = mesh_from_sdf(sdf, grid, 0.0, decode.min_voxels, decode.min_main_share)
        seconds[f"tsdf {resolution} mesh"] = time.perf_counter() - start
        if surface.reason is None:
            surface.mesh.apply_translation(-surface.mesh.center_mass)  # as mesh_decoded places a decode
        meshes[f"tsdf {resolution}"] = (surface.mesh if surface.reason is None else None, surface.reason)
    return meshes, seconds


def shape_rows(job: tuple[Path, str], margin: int, decode, grasps, seed: int, truncation: float) -> tuple[list, dict]:
    """One shape's per-variant rows (graspness, grasps, why no mesh) and the seconds of its grid steps."""
    path, shape_id = job
    meshes, seconds = reconstructions(read_mesh(path), margin, decode, truncation)
    rows = []
    with tempfile.TemporaryDirectory() as folder:
        for variant, (mesh, reason) in meshes.items():
            row = {"shape_id": shape_id, "variant": variant, "meshed": mesh is not None, "reason": reason}
            if mesh is not None:
                file = path
                if variant != "original":
                    file = mesh_path(folder, f"{shape_id}_{variant.replace(' ', '_')}", GENERATED_SUFFIX)
                    write_obj(mesh, file)
                score, count = mesh_graspness(file, shape_id, grasps, seed)
                row |= {"graspness": score, "grasps": count, "faces": len(mesh.faces)}
            rows.append(row)
    return rows, seconds


def summarize(per_shape: pd.DataFrame) -> pd.DataFrame:
    """One row per variant: its paired comparison with the original over the shapes that meshed."""
    before = per_shape[per_shape.variant == "original"].set_index("shape_id").graspness
    rows = []
    for variant in VARIANTS:
        part = per_shape[per_shape.variant == variant].set_index("shape_id")
        after = part.graspness[part.meshed]
        rows.append(
            {"variant": variant, "shapes": len(part), "meshed": int(part.meshed.sum())}
            | paired_graspness_kept(after.to_numpy(), before[after.index].to_numpy())
            | {"grasps_after_mean": float(part.grasps[part.meshed].mean())}
        )
    return pd.DataFrame(rows)


def run(project: Path, n_shapes: int, seed: int, workers: int | None, truncation: float, out: Path) -> str:
    """The study (module docstring) on ``n_shapes`` train shapes of ``project`` drawn with ``seed``, on ``workers``
    processes (None: the project's ``n_jobs``); writes its tables into the folder ``out``; the markdown table."""
    project = project.resolve()
    params = load_params(project / "params.yaml")
    _, mesh_dir, suffix = corpus_files("original")
    shapes = read_table(project / SHAPES_TABLE)  # with the split
    train = shapes.shape_id[shapes.split == "train"].to_numpy()
    chosen = sorted(np.random.default_rng(seed).choice(train, size=min(n_shapes, len(train)), replace=False))
    jobs = [(mesh_path(project / mesh_dir, shape_id, suffix), shape_id) for shape_id in chosen]
    margin, decode = params.voxelize.margin, params.generate.decode

    start = time.perf_counter()
    results = parallel_map(
        lambda job: shape_rows(job, margin, decode, params.grasps, params.seed, truncation),
        jobs,
        workers or params.workers,
        "round trips",
    )
    seconds = time.perf_counter() - start
    per_shape = pd.DataFrame([row for rows, _ in results for row in rows])
    rows = summarize(per_shape)
    steps = pd.DataFrame([s for _, s in results])

    write_csv(per_shape, out / "per_shape.csv")
    write_csv(rows, out / "rows.csv")
    settings = {
        "project": str(project),
        "shapes": len(chosen),
        "seed": seed,
        "truncation_voxels": truncation,
        "margin": margin,
        "decode": dataclasses.asdict(decode),
        "grasps_seed": params.seed,
        "n_grasps": params.grasps.sampler.n_grasps,
    }
    write_json({"settings": settings, "rows": rows.replace({np.nan: None}).to_dict("records")}, out / "summary.json")
    timing = {
        "seconds": round(seconds, 1),
        "per_shape_mean": {step: round(float(steps[step].mean()), 3) for step in steps},
        "per_shape_median": {step: round(float(steps[step].median()), 3) for step in steps},
    }
    write_json(timing, out / "timing.json")
    reasons = per_shape[~per_shape.meshed].groupby("variant").reason.value_counts()
    if len(reasons):
        log.info("not meshed:\n%s", reasons.to_string())
    log.info("%d shapes in %.0f s; seconds per shape (mean): %s", len(chosen), seconds, timing["per_shape_mean"])
    return paired_graspness_kept_markdown(rows)
