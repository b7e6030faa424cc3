"""Ingest keeps an object's real size when asked, rejects what the gripper cannot take, and rejects a shape whose
voxel grid at the AutoEncoder's resolution is (nearly) empty ([trust] #62 item 3)."""

from __future__ import annotations

import numpy as np
import trimesh

from graspaug.augment.corpus import ingest_source, occupied_voxels
from graspaug.geometry.settings import SurfaceSettings
from graspaug.io.sources import Source

REAL = SurfaceSettings(size="real", resolution=64, finest_resolution=64)


def fork(length: float = 0.18) -> trimesh.Trimesh:
    """A YCB-like fork, metres: a thin handle plate along x and a wider head plate at one end, 4 mm thick."""
    handle = trimesh.creation.box(extents=[0.62 * length, 0.014, 0.004])
    handle.apply_translation([-0.19 * length, 0.0, 0.0])
    head = trimesh.creation.box(extents=[0.40 * length, 0.026, 0.004])
    head.apply_translation([0.30 * length, 0.0, 0.0])
    return trimesh.util.concatenate([handle, head])


def source_of(mesh: trimesh.Trimesh, folder, name: str, unit_scale: float = 1.0) -> Source:
    path = folder / f"{name}.stl"
    mesh.export(path)
    return Source(name, f"folder:{name}.stl", path, unit_scale)


def test_real_size_keeps_an_18_cm_fork_18_cm_long(tmp_path):
    source = source_of(fork(), tmp_path, "fork")
    real = ingest_source(source, 10**6, 10.0, REAL, tmp_path)
    assert real["ok"], real.get("reason")
    assert abs(max(real["extent_x"], real["extent_y"], real["extent_z"]) - 0.18) < 0.004
    assert abs(real["scale"] - 1.0) < 1e-12
    normalized = ingest_source(source, 10**6, 10.0, SurfaceSettings(resolution=64, finest_resolution=64), tmp_path)
    assert normalized["ok"] and max(normalized["extent_x"], normalized["extent_y"]) > 0.3  # the old rule: ~0.44 m


def test_real_size_follows_the_unit_scale(tmp_path):
    millimetres = fork()
    millimetres.apply_scale(1000.0)
    row = ingest_source(source_of(millimetres, tmp_path, "fork_mm", 0.001), 10**6, 10.0, REAL, tmp_path)
    assert row["ok"] and abs(row["extent_x"] - 0.18) < 0.004


def test_real_size_rejects_what_the_gripper_cannot_take(tmp_path):
    big = ingest_source(
        source_of(trimesh.creation.box(extents=[0.2, 0.15, 0.12]), tmp_path, "crate"), 10**6, 10.0, REAL, tmp_path
    )
    assert not big["ok"] and big["reason"].startswith(
        "too large for the gripper: smallest side 0.120 m > max_width=0.08"
    )
    crumb = ingest_source(
        source_of(trimesh.creation.icosphere(radius=0.003), tmp_path, "crumb"), 10**6, 10.0, REAL, tmp_path
    )
    assert not crumb["ok"] and crumb["reason"].startswith("too small: largest extent 0.006")


def test_a_shape_empty_at_the_voxel_resolution_is_rejected_with_its_reason(tmp_path):
    source = source_of(fork(), tmp_path, "fork")
    kept = ingest_source(source, 10**6, 10.0, REAL, tmp_path)
    mesh = trimesh.load(tmp_path / "fork.ply")
    assert occupied_voxels(mesh, 16, 1) == 0 and occupied_voxels(mesh, 128, 1) > 0  # thin: empty at 16³ only
    assert kept["ok"]
    empty = ingest_source(source, 10**6, 10.0, REAL, tmp_path, voxel_grid=(16, 1), min_voxels=8)
    assert not empty["ok"] and empty["reason"] == "empty voxel grid: 0 occupied voxels at 16³ < min_voxels=8"
    fine = ingest_source(source, 10**6, 10.0, REAL, tmp_path, voxel_grid=(128, 1), min_voxels=8)
    assert fine["ok"]
    cube = ingest_source(
        source_of(trimesh.creation.box(extents=[0.05] * 3), tmp_path, "cube"), 10**6, 10.0, REAL, tmp_path, (16, 1), 8
    )
    assert cube["ok"] and np.isclose(cube["extent_x"], 0.05, atol=0.002)


def test_fit_keeps_what_the_gripper_takes_and_shrinks_what_it_cannot(tmp_path):
    """Size `fit`: the fork keeps its 18 cm; a 20 × 15 × 12 cm crate keeps its shape, scaled until its narrowest side
    is 0.9 of the gripper's opening (its scale in the row); a crumb is still too small."""
    fit = SurfaceSettings(size="fit", resolution=64, finest_resolution=64)
    kept = ingest_source(source_of(fork(), tmp_path, "fork"), 10**6, 10.0, fit, tmp_path)
    assert kept["ok"] and abs(kept["scale"] - 1.0) < 1e-12
    assert abs(max(kept["extent_x"], kept["extent_y"], kept["extent_z"]) - 0.18) < 0.004
    crate = trimesh.creation.box(extents=[0.2, 0.15, 0.12])
    shrunk = ingest_source(source_of(crate, tmp_path, "crate"), 10**6, 10.0, fit, tmp_path)
    assert shrunk["ok"], shrunk.get("reason")
    extents = sorted([shrunk["extent_x"], shrunk["extent_y"], shrunk["extent_z"]])
    assert np.allclose(extents, np.array([0.12, 0.15, 0.2]) * 0.072 / 0.12, rtol=0.02)
    assert abs(shrunk["scale"] - 0.6) < 0.01
    crumb = ingest_source(
        source_of(trimesh.creation.icosphere(radius=0.003), tmp_path, "crumb"), 10**6, 10.0, fit, tmp_path
    )
    assert not crumb["ok"] and crumb["reason"].startswith("too small")


def test_fit_refuses_to_shrink_past_half_and_names_the_unit_mistake(tmp_path):
    """The issue's case: an 80 × 50 × 100 mm box written in millimetres was kept at scale 0.00144 (a metre-wide box
    shrunk); `fit` refuses a scale below fit_min_scale, and a shape 100× too wide or more names --unit-scale."""
    fit = SurfaceSettings(size="fit", resolution=32, finest_resolution=32)
    box_mm = trimesh.creation.box(extents=[80.0, 50.0, 100.0])
    read_as_metres = ingest_source(source_of(box_mm, tmp_path, "box_mm"), 10**6, 10.0, fit, tmp_path)
    assert not read_as_metres["ok"] and read_as_metres["reason"].startswith("too large for the gripper")
    assert "scale it by 0.00144 < 0.5" in read_as_metres["reason"] and "--unit-scale 0.001" in read_as_metres["reason"]
    with_unit = ingest_source(source_of(box_mm, tmp_path, "box_mm", unit_scale=0.001), 10**6, 10.0, fit, tmp_path)
    assert with_unit["ok"] and abs(with_unit["scale"] - 0.001) < 1e-12  # in metres: 5 cm narrow, kept as it is
    big = trimesh.creation.box(extents=[0.4, 0.3, 0.2])  # a real 20 cm-deep object: fitting would take it to 0.36
    halved = ingest_source(source_of(big, tmp_path, "big"), 10**6, 10.0, fit, tmp_path)
    assert not halved["ok"] and "scale it by 0.36 < 0.5" in halved["reason"] and "unit" not in halved["reason"]
    lowered = SurfaceSettings(size="fit", resolution=32, finest_resolution=32, fit_min_scale=0.2)  # real_objects'
    assert ingest_source(source_of(big, tmp_path, "big_kept"), 10**6, 10.0, lowered, tmp_path)["ok"]
    real = ingest_source(source_of(box_mm, tmp_path, "box_real"), 10**6, 10.0, REAL, tmp_path)
    assert not real["ok"] and "smallest side 50.000 m > max_width=0.08 m" in real["reason"]
    assert "--unit-scale 0.001" in real["reason"]  # the same hint at real size
