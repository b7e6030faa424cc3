"""Scans and textured exports become the solids they describe, not hollow shells (issue #20).

Every mesh is built here (``scan_meshes``) with its true volume; ingest's volume is
compared in the source frame (normalized volume / scale³).
"""

import dataclasses

import numpy as np
import pytest
import trimesh

from graspaug.geometry.closing import close_surface, fill_open_mesh
from graspaug.geometry.loading import MeshRejected, load_shape
from graspaug.geometry.prepare import prepare_shape
from graspaug.geometry.settings import SurfaceSettings

from . import scan_meshes

SETTINGS = SurfaceSettings()


def write(tmp_path, name, mesh_or_text):
    if isinstance(mesh_or_text, str):
        path = tmp_path / f"{name}.obj"
        path.write_text(mesh_or_text)
    else:
        path = tmp_path / f"{name}.ply"
        mesh_or_text.export(path)
    return path


def ingested(path, settings=SETTINGS):
    """(source-frame volume, PreparedShape) as the ingest stage makes them."""
    prepared = prepare_shape(load_shape(path), settings)
    return prepared.mesh.volume / prepared.normalization.scale**3, prepared


def test_a_textured_obj_loads_split_at_every_seam(tmp_path):
    """The premise: kept as loaded, the file's faces share no vertex (so the fix is needed)."""
    text, _ = scan_meshes.seamed_cylinder()
    raw = trimesh.load(write(tmp_path, "can", text), process=False, force="mesh")
    raw.merge_vertices()  # what loading did so far: UVs differ, nothing merges
    assert raw.body_count == len(raw.faces) and not raw.is_watertight
    loaded = load_shape(tmp_path / "can.obj")
    assert loaded.closed_by == "merged" and loaded.mesh.is_watertight and loaded.mesh.body_count == 1


@pytest.mark.parametrize(
    "name, closed_by",
    [("seamed_cylinder", "merged"), ("seamed_box", "merged"), ("holed_sphere", "filled"), ("scan_like_can", "filled")],
)
def test_open_and_seamed_meshes_come_in_as_solids(tmp_path, name, closed_by):
    mesh_or_text, true_volume = getattr(scan_meshes, name)()
    volume, prepared = ingested(write(tmp_path, name, mesh_or_text))
    assert prepared.closed_by == closed_by
    assert volume == pytest.approx(true_volume, rel=0.05)
    assert prepared.mesh.is_watertight and prepared.mesh.body_count == 1
    assert prepared.hull_fill > 0.9  # convex solids fill their hull (a shell: about 0.1)


def test_an_open_top_mug_keeps_its_cavity(tmp_path):
    text, true_volume = scan_meshes.mug()
    assert not load_shape(write(tmp_path, "mug", text)).mesh.is_watertight  # open after merging: it is filled
    volume, prepared = ingested(tmp_path / "mug.obj")
    assert prepared.closed_by == "filled"
    assert volume == pytest.approx(true_volume, rel=0.10)  # walls and base, not the cavity
    assert prepared.hull_fill < 0.35


def test_two_far_apart_closed_bodies_are_still_rejected(tmp_path):
    text, _ = scan_meshes.far_apart_bodies()
    with pytest.raises(MeshRejected, match="^in pieces"):
        ingested(write(tmp_path, "two", text))


def test_a_hole_wider_than_max_gap_is_rejected_with_that_reason(tmp_path):
    ball, true_volume = scan_meshes.holed_sphere(hole=0.012)  # 12 mm holes on an 8 cm ball
    path = write(tmp_path, "ball", ball)
    with pytest.raises(MeshRejected, match=r"^open: .* max_gap=0.05 of the largest extent \(4.0 mm\)"):
        ingested(path)
    volume, prepared = ingested(path, dataclasses.replace(SETTINGS, max_gap=0.25))
    assert prepared.closed_by == "filled" and volume == pytest.approx(true_volume, rel=0.05)


def test_closed_meshes_keep_their_triangles_and_default_objects_are_as_is(default_loaded):
    torus = trimesh.creation.torus(major_radius=0.04, minor_radius=0.012)
    closed = close_surface(torus, resolution=96, face_budget=5000, max_gap=0.05)
    assert not closed.filled and len(closed.mesh.faces) == len(torus.faces)
    for _, loaded in default_loaded:
        assert loaded.closed_by == "as_is" and loaded.parts


def test_an_open_sheet_encloses_nothing():
    cup = trimesh.creation.cylinder(radius=0.03, height=0.05, sections=48)
    cup.update_faces(cup.face_normals[:, 2] < 0.9)  # no lid: a zero-thickness open cup
    filled = fill_open_mesh(cup, resolution=64, face_budget=3000, max_gap=0.05)
    assert filled.enclosed < 0.5  # prepare_shape rejects it
    assert filled.mesh.volume < 0.01 * np.pi * 0.03**2 * 0.05  # at most the fillet of its inner crease


def test_open_and_multi_body_meshes_are_rebuilt_closed():
    ball, volume = scan_meshes.holed_sphere()
    assert not ball.is_watertight
    closed = close_surface(ball, resolution=64, face_budget=3000, max_gap=0.05).mesh
    assert closed.is_watertight and closed.body_count == 1
    assert closed.volume == pytest.approx(volume, rel=0.03)  # solid, not a shell
    boxes = trimesh.util.concatenate(  # overlapping closed bodies
        [trimesh.creation.box(extents=(0.04, 0.02, 0.02)), trimesh.creation.box(extents=(0.02, 0.02, 0.04))]
    )
    closed = close_surface(boxes, resolution=64, face_budget=3000, max_gap=0.05).mesh
    assert closed.is_watertight and closed.body_count == 1
    assert closed.volume == pytest.approx(0.04 * 0.02 * 0.02 + 2 * 0.01 * 0.02 * 0.02, rel=0.05)
    cup = trimesh.creation.cylinder(radius=0.03, height=0.05, sections=48)
    cup.update_faces(cup.face_normals[:, 2] < 0.9)  # no lid: an open sheet bounds (almost) no volume
    closed = close_surface(cup, resolution=64, face_budget=3000, max_gap=0.05).mesh
    assert closed.volume < 0.01 * np.pi * 0.03**2 * 0.05  # at most the fillet of its inner crease
