"""Stage ``voxelize``: every shape's outer surface → a solid R³ occupancy grid in ``data/voxels.npz``, and with
``ae.net.output: sdf`` its truncated signed distance too (:func:`graspaug.geometry.sdf.truncated_distance_grid`)."""

from __future__ import annotations

import logging
import time
from pathlib import Path

import numpy as np

from graspaug.geometry.sdf import truncated_distance_grid
from graspaug.geometry.voxelize import fit_grid, voxelize_solid
from graspaug.io.meshes import mesh_path, read_mesh
from graspaug.io.tables import read_table
from graspaug.io.voxels import VoxelSet, write_voxels
from graspaug.pipeline.params.ae import AEParams
from graspaug.pipeline.params.base import params_model
from graspaug.pipeline.params.voxelize import VoxelizeParams
from graspaug.pipeline.paths import OBJECTS_TABLE, SHAPES_DIR, VOXELS

log = logging.getLogger(__name__)

Params = params_model("The params the `voxelize` stage reads.", ae=AEParams, voxelize=VoxelizeParams)


def voxelize_file(
    path: Path, resolution: int, margin: int, truncation: float | None = None
) -> tuple[np.ndarray, float, np.ndarray, np.ndarray | None]:
    """Occupancy (R, R, R) bool, pitch (m), grid origin (3,) m of one mesh file, and with a ``truncation``
    (voxels) its truncated signed distance / truncation (R, R, R) float32, else None."""
    mesh = read_mesh(path)
    grid = fit_grid(mesh.bounds, resolution, margin)
    occupancy = voxelize_solid(mesh.vertices, mesh.faces, grid)
    if truncation is None:
        return occupancy, grid.pitch, grid.origin, None
    return (
        occupancy,
        grid.pitch,
        grid.origin,
        truncated_distance_grid(mesh.vertices, mesh.faces, grid, truncation) / truncation,
    )


def run(params: Params) -> None:
    """Run the stage with ``params``."""
    from graspaug.parallel import parallel_map

    start = time.perf_counter()
    cfg = params.voxelize
    shape_ids = list(read_table(OBJECTS_TABLE)["shape_id"])
    paths = [mesh_path(SHAPES_DIR.resolve(), s) for s in shape_ids]  # workers may have another cwd
    truncation = params.ae.net.truncation if params.ae.net.output == "sdf" else None
    out = parallel_map(
        lambda p: voxelize_file(p, cfg.resolution, cfg.margin, truncation), paths, params.workers, "voxelize"
    )
    voxels = VoxelSet(
        shape_id=np.array(shape_ids),
        occupancy=np.stack([o[0] for o in out]),
        pitch=np.array([o[1] for o in out]),
        origin=np.stack([o[2] for o in out]),
        sdf=None if truncation is None else np.stack([o[3] for o in out]).astype(np.float32),
        truncation=truncation,
    )
    write_voxels(voxels, VOXELS)
    fill = voxels.occupancy.mean(axis=(1, 2, 3))
    log.info(
        "voxelize: %d shapes at %d³, mean fill %.3f, in %.1f s",
        len(shape_ids),
        cfg.resolution,
        fill.mean(),
        time.perf_counter() - start,
    )


if __name__ == "__main__":
    from graspaug.pipeline.entry import stage_main

    stage_main(__spec__.name)
