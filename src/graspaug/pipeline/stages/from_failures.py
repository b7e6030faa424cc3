"""``graspaug from-failures``: new training shapes near the objects a planner fails on (the lifelong loop's
generation step). No DVC stage: a command whose adapter sits here as it knows the project's files.

The failure objects are a folder of meshes (closed, scaled, voxelized and encoded as the corpus is) or the ``worst``
*validation* objects of one of this project's networks (the test split never chooses). Their nearest train shapes in
latent space anchor interpolants decoded and meshed as ``generate`` does; a failure object is never a parent.

Writes, all at once, into ``out`` (refused before any work if it holds a file this command did not write, is a link
or lies inside an input; only the files of its last run are replaced, :mod:`graspaug.io.outputs`):
``meshes/failure_<order>.obj`` (m), ``index.csv`` (per shape: its failure object, parents, ``alpha``, size),
``failures.csv`` (the objects, worst first: shapes, rejected decodes and why none), ``rejects.csv`` (with the failure
each decode served), ``skipped.csv`` (unusable files, and why).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from graspaug.augment.decode import mesh_batches
from graspaug.augment.failures import failure_shapes, failure_summary, log_failure_summary
from graspaug.augment.pools import base_set
from graspaug.device import resolve_device
from graspaug.errors import DataError
from graspaug.experiments.lifelong.numbers import failure_anchors, validation_errors
from graspaug.io.checkpoints import load_autoencoder
from graspaug.io.meshes import mesh_path, write_obj
from graspaug.io.outputs import check_output_folder, output_folder
from graspaug.io.tables import read_table
from graspaug.io.voxels import read_voxels
from graspaug.pipeline import paths
from graspaug.pipeline.params.ae import AEParams
from graspaug.pipeline.params.base import params_model
from graspaug.pipeline.params.generate import GenerateParams
from graspaug.pipeline.params.gqcnn import GQCNNParams
from graspaug.pipeline.params.ingest import IngestParams
from graspaug.pipeline.params.score import ScoreParams
from graspaug.pipeline.params.voxelize import VoxelizeParams
from graspaug.training.autoencoder import encode_meshes

COMMAND = "from-failures"

Params = params_model(
    "The params `graspaug from-failures` reads.",
    ingest=IngestParams,
    voxelize=VoxelizeParams,
    ae=AEParams,
    generate=GenerateParams,
    gqcnn=GQCNNParams,
    score=ScoreParams,
)


def run(params: Params, folder, network: str | None, worst: int, count: int, per_failure: int, out, force=False):
    from graspaug.sim.objects import folder_meshes

    if (folder is None) == (network is None):
        raise DataError("give either a folder of failure meshes or --network (its worst validation objects)")
    if min(count, per_failure, worst) < 1:
        raise DataError(f"--count, --per-failure, --worst must be at least 1; got {count}, {per_failure}, {worst}")
    inputs = [folder, "data", "models"]
    check_output_folder(out, COMMAND, inputs, force)
    device, (ae, _, _) = resolve_device(params.device), load_autoencoder(paths.AE_CRITIC_MODEL, params.ae.net)
    shapes, latents = read_table(paths.SHAPES_TABLE), read_table(paths.LATENTS).set_index("shape_id")
    train, skipped = set(shapes.shape_id[shapes.split == "train"]), {}
    if network is not None:  # this project's network: its worst validation objects, never train shapes here
        seed_dirs = {s: paths.gqcnn_seed_dir(s) for s in params.gqcnn.seeds}
        index = read_table(paths.gqcnn_dir("original") / "index.parquet")
        errors, validation = validation_errors(seed_dirs, network, index)
        names = list(errors.index[:worst])
        failure_z, train = np.stack(latents.z.loc[names].to_numpy()), train - set(validation)
    else:
        ingest, grid = params.ingest, params.voxelize
        try:
            meshes, skipped = folder_meshes(
                Path(folder), ingest.surface, ingest.max_faces, ingest.max_file_mb, label=COMMAND
            )
        except ValueError as exc:
            raise DataError(str(exc).replace("sim.objects_path", "the failure folder")) from None
        names = [name for name, _ in meshes]
        failure_z = encode_meshes(ae, [m for _, m in meshes], grid.resolution, grid.margin, device)
        errors = pd.DataFrame(index=pd.Index(names, name="object"))
    ids = shapes.shape_id[shapes.shape_id.isin(train)].to_numpy()
    pool = base_set(ids, latents.reset_index(), read_table(paths.SCORES), read_voxels(paths.VOXELS), params.score.k)
    anchors, served = failure_anchors(pool.z, failure_z, per_failure)
    served = [names[f] for f in served]  # the failure object each anchor serves
    run_batch = mesh_batches(ae, device, pool, params.generate.decode, params.workers, "from failures")
    index, rejects, kept, notes = failure_shapes(pool, anchors, served, count, params.generate, run_batch)
    summary = failure_summary(names, served, index, rejects)
    with output_folder(out, COMMAND, inputs, force) as tmp:
        (tmp / "meshes").mkdir()
        for shape_id, decoded in zip(index.shape_id, kept):
            write_obj(decoded.mesh, mesh_path(tmp / "meshes", shape_id, ".obj"))
        index.drop(columns=["z", "base_size", "pool", "split"]).to_csv(tmp / "index.csv", index=False)
        errors.assign(failure=errors.index.isin(names)).join(summary.set_index("failure")).to_csv(tmp / "failures.csv")
        rejects.to_csv(tmp / "rejects.csv", index=False)
        pd.DataFrame({"file": list(skipped), "reason": list(skipped.values())}).to_csv(tmp / "skipped.csv", index=False)
    log_failure_summary(summary, notes, out)
