"""Loading real and broken mesh files; every broken kind gets its reason."""

import numpy as np
import pytest
import trimesh

from graspaug.geometry.loading import MeshRejected, load_shape
from graspaug.io.sources import folder_sources, pybullet_data_root, pybullet_sources


def write_broken_corpus(folder):
    """A folder with one file of every broken kind, and the reason prefix each must get."""
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "garbage.obj").write_bytes(bytes(np.random.default_rng(0).integers(0, 256, 4096, dtype=np.uint8)))
    box_ply = trimesh.exchange.ply.export_ply(trimesh.creation.box(), encoding="binary")
    (folder / "truncated.ply").write_bytes(box_ply[: len(box_ply) // 2])
    (folder / "nan.obj").write_text("v nan 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 3 4\nf 1 4 2\nf 2 4 3\n")
    (folder / "triangle.obj").write_text("v 0 0 0\nv 0.05 0 0\nv 0 0.05 0\nf 1 2 3\n")
    # a flat sheet tilted against every axis: flat along its own principal directions
    (folder / "tilted.obj").write_text("v 0 0 0\nv 0.05 0 0.01\nv 0 0.05 0.02\nv 0.05 0.05 0.03\nf 1 2 3\nf 2 4 3\n")
    (folder / "empty.stl").write_bytes(b"")
    trimesh.creation.icosphere(subdivisions=6, radius=0.03).export(folder / "huge.ply")  # 81,920 faces
    (folder / "points.ply").write_text(
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float "
        "z\nend_header\n0 0 0\n1 0 0\n0 1 0\n"
    )
    return {
        "garbage": "no triangles",
        "truncated": "unreadable",
        "nan": "non-finite vertex coordinates",
        "triangle": "degenerate: flat",
        "tilted": "degenerate: flat",
        "empty": "empty file",
        "huge": "too many faces: 81920 > max_faces=50000",
        "points": "not a mesh",
    }


def test_every_broken_kind_is_rejected_with_its_reason(tmp_path):
    expected = write_broken_corpus(tmp_path / "broken")
    sources = folder_sources(tmp_path / "broken")
    assert sorted(s.path.stem for s in sources) == sorted(expected)
    for source in sources:
        stem = source.path.stem
        with pytest.raises(MeshRejected) as exc:
            load_shape(source.path, max_faces=50_000)
        assert str(exc.value).startswith(expected[stem]), (stem, str(exc.value))
        assert "\n" not in str(exc.value)


def test_too_large_file_is_rejected_before_reading(tmp_path):
    path = tmp_path / "big.stl"
    trimesh.creation.icosphere(subdivisions=4).export(path)
    with pytest.raises(MeshRejected, match=r"^file too large: .* > max_file_mb=0.01"):
        load_shape(path, max_file_mb=0.01)


def test_default_corpus_sources():
    sources = pybullet_sources()
    assert len(sources) == 1000
    assert sources[0].shape_id == "rnd_000" and sources[-1].shape_id == "rnd_999"
    assert sources[0].name == "pybullet_data:random_urdfs/000/000.obj"
    assert all(s.unit_scale == 0.015 for s in sources)
    assert sources[0].path == pybullet_data_root() / "random_urdfs/000/000.obj"


def test_the_nan_object_of_the_default_corpus_is_rejected():
    (source,) = [s for s in pybullet_sources() if s.shape_id == "rnd_168"]
    with pytest.raises(MeshRejected, match="non-finite"):
        load_shape(source.path, source.unit_scale)


def test_default_objects_load_as_convex_parts_in_meters(default_loaded):
    for source, loaded in default_loaded:
        assert 1 <= len(loaded.parts)
        assert 0.05 < loaded.mesh.extents.max() < 0.2  # the URDF scale 0.015 is applied
        text = source.path.read_text()
        assert len(loaded.parts) == text.count("\no ") + text.startswith("o ")


def test_folder_ids_are_stable_and_unique(tmp_path):
    for rel in ("a/Mug 1.obj", "a/mug_1.stl", "b/c/bowl.ply"):
        path = tmp_path / rel
        path.parent.mkdir(parents=True, exist_ok=True)
        trimesh.creation.box().export(path)
    ids = [s.shape_id for s in folder_sources(tmp_path)]
    assert ids == ["f_a_mug_1", "f_a_mug_1_2", "f_b_c_bowl"]
    assert [s.name for s in folder_sources(tmp_path)][2] == "folder:b/c/bowl.ply"


def test_a_convex_body_is_rebuilt_as_one_part_and_sized(tmp_path):
    from graspaug.geometry.prepare import SurfaceSettings, prepare_shape

    path = tmp_path / "box.stl"
    trimesh.creation.box(extents=(0.1, 0.06, 0.03)).export(path)
    loaded = load_shape(path)
    assert len(loaded.parts) == 1  # one closed convex body counts as one convex part
    prepared = prepare_shape(loaded, SurfaceSettings(size_rule="mid", size_m=0.06))
    assert np.allclose(sorted(prepared.mesh.extents), [0.03, 0.06, 0.1], atol=1e-3)
    assert np.allclose(prepared.mesh.center_mass, 0, atol=1e-6)


def test_a_closed_non_convex_body_keeps_its_triangles(tmp_path):
    from graspaug.geometry.prepare import SurfaceSettings, prepare_shape

    torus = trimesh.creation.torus(major_radius=0.04, minor_radius=0.012)
    path = tmp_path / "ring.ply"
    torus.export(path)
    loaded = load_shape(path)
    assert loaded.parts == []
    prepared = prepare_shape(loaded, SurfaceSettings())
    assert len(prepared.mesh.faces) == len(torus.faces) < SurfaceSettings().face_budget
    scale = prepared.normalization.scale
    assert np.allclose(
        np.sort(prepared.mesh.vertices, axis=0),
        np.sort(torus.vertices * scale + prepared.normalization.offset, axis=0),
        atol=0.5e-6 * scale + 1e-12,  # read to 1 µm (VERTEX_DIGITS)
    )


def test_a_file_in_millimetres_reads_as_the_same_metres(tmp_path):
    """A float32 STL of a scan in metres and its copy in millimetres (its float32 vertices ×1000, 1e-9 m of noise
    apart) read with unit scale 0.001 give the same vertices, bit for bit: coordinates are read to 1 µm, and the
    decimator after them sees one mesh, not two triangulations."""
    rng = np.random.default_rng(0)
    mesh = trimesh.creation.icosphere(3, 0.03)
    mesh.vertices = np.round(mesh.vertices + rng.uniform(-0.001, 0.001, mesh.vertices.shape), 5)  # 10 µm digits
    mesh.export(tmp_path / "m.stl")
    millimetres = trimesh.load(tmp_path / "m.stl", process=False)
    millimetres.apply_scale(1000.0)
    millimetres.export(tmp_path / "mm.stl")
    in_m, in_mm = load_shape(tmp_path / "m.stl"), load_shape(tmp_path / "mm.stl", unit_scale=0.001)
    raw_m = trimesh.load(tmp_path / "m.stl", process=False).vertices
    raw_mm = trimesh.load(tmp_path / "mm.stl", process=False).vertices * 0.001
    assert not np.array_equal(raw_m, raw_mm) and np.abs(raw_m - raw_mm).max() < 1e-8  # float noise apart
    np.testing.assert_array_equal(in_m.mesh.faces, in_mm.mesh.faces)
    np.testing.assert_array_equal(in_m.mesh.vertices, in_mm.mesh.vertices)
