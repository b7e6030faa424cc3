"""``graspaug from-failures``: new training shapes near the objects a planner fails on (the lifelong
loop's entry point for a planner trained elsewhere). No DVC stage: a command whose adapter sits here as
it knows the project's files; it needs ``train_ae``, ``embed`` and ``score`` to have run.

A folder of meshes (objects the user's planner missed) is loaded, closed and scaled as the corpus is,
voxelized as ``voxelize`` does and encoded by this project's AE-Critic. Each failure object's
``per_failure`` nearest train shapes in latent space become anchors
(:func:`graspaug.experiments.lifelong.failure_anchors`), each interpolated with its neighbours among
the train shapes, decoded and meshed as ``generate`` does (:func:`graspaug.generation_meshes.failure_shapes`).
A failure object is never a parent: it only points at the train shapes to generate from.

Writes, all at once: ``<out>/meshes/failure_<order>.obj`` (m), ``<out>/index.csv`` (per shape: its failure
object, anchor ``parent_a``, neighbour ``parent_b``, ``alpha``, size), ``<out>/rejects.csv`` and
``<out>/skipped.csv`` (files of the folder that could not be used, and why).
"""

from __future__ import annotations

import logging
from functools import partial
from pathlib import Path

import numpy as np
import pandas as pd
import torch

from graspaug import paths
from graspaug.device import resolve_device
from graspaug.errors import DataError
from graspaug.experiments.lifelong import failure_anchors
from graspaug.generation_meshes import base_set, failure_shapes, mesh_batches
from graspaug.geometry.voxelize import fit_grid, voxelize_solid
from graspaug.io.atomic import atomic_path
from graspaug.io.checkpoints import load_autoencoder
from graspaug.io.meshes import mesh_path, write_obj
from graspaug.io.tables import read_table
from graspaug.io.voxels import read_voxels
from graspaug.params.ae import AEParams
from graspaug.params.base import params_model
from graspaug.params.generate import GenerateParams
from graspaug.params.ingest import IngestParams
from graspaug.params.score import ScoreParams
from graspaug.params.voxelize import VoxelizeParams
from graspaug.training.autoencoder import encode

log = logging.getLogger(__name__)

Params = params_model(
    "The params `graspaug from-failures` reads.",
    ingest=IngestParams,
    voxelize=VoxelizeParams,
    ae=AEParams,
    generate=GenerateParams,
    score=ScoreParams,
)


def run(params: Params, folder: Path, count: int, per_failure: int, out: Path) -> None:
    from graspaug.sim.objects import folder_meshes

    if count < 1 or per_failure < 1:
        raise DataError(f"--count and --per-failure must be at least 1; got {count} and {per_failure}")
    ingest, grid = params.ingest, params.voxelize
    try:
        meshes, skipped = folder_meshes(Path(folder), ingest.surface, ingest.max_faces, ingest.max_file_mb)
    except ValueError as exc:
        raise DataError(str(exc).replace("sim.objects_path", "the failure folder")) from None
    occupancy = []
    for _, mesh in meshes:
        cells = fit_grid(mesh.bounds, grid.resolution, grid.margin)
        occupancy.append(voxelize_solid(mesh.vertices, mesh.faces, cells))
    device = resolve_device(params.device)
    ae, _, _ = load_autoencoder(paths.AE_CRITIC_MODEL, params.ae.net)
    failure_z = encode(ae, torch.from_numpy(np.stack(occupancy)[:, None].astype(np.uint8)), device)
    shapes, latents = read_table(paths.SHAPES_TABLE), read_table(paths.LATENTS)
    train = shapes.shape_id[shapes.split == "train"].to_numpy()
    pool = base_set(train, latents, read_table(paths.SCORES), read_voxels(paths.VOXELS), params.score.k)
    anchors, served = failure_anchors(pool.z, failure_z, per_failure)
    names = [meshes[f][0] for f in served]
    run_batch = partial(mesh_batches, ae, device, settings=params.generate.decode, workers=params.workers)
    index, rejects, kept, notes = failure_shapes(
        pool, anchors, names, count, params.generate, run_batch(pool, label="from failures")
    )
    for note in notes:  # how the stream was widened
        log.info("from-failures: %s", note)
    with atomic_path(out, directory=True) as tmp:
        (tmp / "meshes").mkdir()
        for shape_id, decoded in zip(index.shape_id, kept):
            write_obj(decoded.mesh, mesh_path(tmp / "meshes", shape_id, ".obj"))
        index.drop(columns=["z", "base_size", "pool", "split"]).to_csv(tmp / "index.csv", index=False)
        rejects.to_csv(tmp / "rejects.csv", index=False)
        pd.DataFrame({"file": list(skipped), "reason": list(skipped.values())}).to_csv(tmp / "skipped.csv", index=False)
    shapes = f"{len(index)} shapes near {len(meshes)} failure objects ({len(skipped)} files skipped)"
    log.info("from-failures: %s in %s", shapes, out)
