"""The voxelize stage's per-file work: occupancy, and with a truncation the signed distances the AE then reads."""

import numpy as np
import pandas as pd
import trimesh

from graspaug.io.voxels import VoxelSet, write_voxels
from graspaug.pipeline.stages.voxelize import voxelize_file
from graspaug.training.autoencoder import grids_by_split


def test_a_file_gives_its_occupancy_and_with_a_truncation_its_signed_distances_of_the_same_inside(tmp_path):
    meshes = {
        "box": trimesh.creation.box(extents=(0.08, 0.05, 0.03)),
        "ring": trimesh.creation.annulus(0.01, 0.03, 0.02),
    }
    rows = {}
    for name, mesh in meshes.items():
        mesh.export(tmp_path / f"{name}.ply")
        occupancy, pitch, origin, none = voxelize_file(tmp_path / f"{name}.ply", 16, 1)
        assert none is None and occupancy.dtype == bool and occupancy.any()
        again, _, _, sdf = voxelize_file(tmp_path / f"{name}.ply", 16, 1, truncation=3.0)
        assert np.array_equal(again, occupancy) and sdf.dtype == np.float32
        assert np.array_equal(sdf < 0, occupancy) and np.abs(sdf).max() <= 1  # distance / truncation, the same inside
        rows[name] = (occupancy, pitch, origin, sdf)
    ids = np.array(list(rows))
    voxels = VoxelSet(
        ids,
        np.stack([r[0] for r in rows.values()]),
        np.array([r[1] for r in rows.values()]),
        np.stack([r[2] for r in rows.values()]),
        np.stack([r[3] for r in rows.values()]),
        3.0,
    )
    write_voxels(voxels, tmp_path / "voxels.npz")
    pd.DataFrame({"shape_id": ids, "split": ["train", "test"]}).to_parquet(tmp_path / "shapes.parquet")
    grids = grids_by_split(tmp_path / "voxels.npz", tmp_path / "shapes.parquet", "sdf")
    assert grids["train"].dtype.is_floating_point and grids["train"].shape == (1, 1, 16, 16, 16)
    assert np.array_equal(grids["test"][0, 0].numpy() < 0, rows["ring"][0])  # the AE sees the occupancy's inside
    occupancy = grids_by_split(tmp_path / "voxels.npz", tmp_path / "shapes.parquet")
    assert occupancy["train"].dtype.is_floating_point is False  # uint8 0/1 as before
