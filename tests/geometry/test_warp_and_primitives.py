"""The no-network baselines' shapes: a real shape under a random smooth warp, and random assemblies of primitives."""

import numpy as np
import pytest
import trimesh

from graspaug.augment.corpus import ingest_source
from graspaug.geometry.prepare import prepare_shape
from graspaug.geometry.primitives import KINDS, Primitive, assembly_mesh, primitive_distance, random_assembly
from graspaug.geometry.settings import PrimitiveSettings, SurfaceSettings, WarpSettings
from graspaug.geometry.warp import Warp, random_warp, warp_mesh, warp_points
from graspaug.io.meshes import write_obj
from graspaug.io.sources import Source

SURFACE = SurfaceSettings()


@pytest.fixture(scope="module")
def ingested(default_loaded):
    """Three default-corpus shapes as ingest leaves them (closed, centred, sized)."""
    return [prepare_shape(loaded, SURFACE).mesh for _, loaded in default_loaded[:3]]


def passes_ingest(mesh, folder, name) -> dict:
    """The ingest stage's row for ``mesh`` written as a file and read back, as a user's mesh is."""
    path = folder / f"{name}.obj"
    write_obj(mesh, path)
    (folder / "out").mkdir(exist_ok=True)
    return ingest_source(Source(name, name, str(path), 1.0), 10**6, 100.0, SURFACE, folder / "out")


def test_an_identity_warp_returns_the_shape(ingested):
    for mesh in ingested:
        out, reason = warp_mesh(mesh, Warp.identity(), SURFACE.size_rule, SURFACE.size_m, SURFACE.face_budget)
        assert reason is None and len(out.vertices) == len(mesh.vertices)
        assert abs(out.volume - mesh.volume) < 1e-6 and np.abs(out.vertices - mesh.vertices).max() < 1e-6


def test_warp_points_moves_a_plane_as_its_steps_say():
    """A scale and a shear keep a plane flat; the bend keeps the z axis' length (an arc, not a stretch)."""
    points = np.random.default_rng(0).uniform(-0.03, 0.03, (200, 3))
    points[:, 2] = 0.01  # the plane z = 1 cm
    warp = Warp(np.eye(3), np.array([1.2, 0.8, 1.0]), np.array([0.3, -0.2]), 0.0, 0.0)
    moved = warp_points(points, warp)
    assert np.allclose(moved[:, 2], 0.01) and np.allclose(moved[:, 0], 1.2 * points[:, 0] + 0.3 * 0.01)
    axis = np.zeros((101, 3))
    axis[:, 2] = np.linspace(-0.05, 0.05, 101)
    axis[0, 0] = axis[-1, 0] = 1e-9  # the largest extent stays z
    bent = warp_points(axis, Warp(np.eye(3), np.ones(3), np.zeros(2), 0.0, 30.0))
    arc = np.linalg.norm(np.diff(bent, axis=0), axis=1).sum()
    assert arc == pytest.approx(0.1, rel=1e-3) and np.ptp(bent[:, 0]) > 0.005


def test_random_warps_are_closed_solids_that_pass_ingest_and_follow_their_seed(ingested, tmp_path):
    settings = WarpSettings()
    for i, mesh in enumerate(ingested):
        made = [
            warp_mesh(mesh, random_warp(np.random.default_rng([7, i]), settings), "mid", 0.06, 5000) for _ in range(2)
        ]
        (out, reason), (again, _) = made
        assert reason is None and out.is_watertight and out.body_count == 1 and len(out.faces) <= 5000
        assert np.array_equal(out.vertices, again.vertices)  # the same stream, the same shape
        assert np.sort(out.extents)[1] == pytest.approx(0.06) and np.abs(out.center_mass).max() < 1e-6
        assert passes_ingest(out, tmp_path, f"warp{i}")["ok"]
        other, _ = warp_mesh(mesh, random_warp(np.random.default_rng([8, i]), settings), "mid", 0.06, 5000)
        assert not np.allclose(np.sort(other.extents), np.sort(out.extents))


@pytest.mark.parametrize("kind", KINDS)
def test_a_primitives_distance_is_signed_and_exact_on_its_axes(kind):
    size = {"ring": [0.3, 0.1, 0.0], "box": [0.2, 0.3, 0.4]}.get(kind, [0.2, 0.3, 0.0])
    part = Primitive(kind, np.array(size), np.eye(3), np.zeros(3))
    far = primitive_distance(np.array([[5.0, 0, 0]]), part)[0]
    surface_x = {"box": 0.2, "cylinder": 0.2, "sphere": 0.2, "capsule": 0.2, "ring": 0.4}[kind]
    assert far == pytest.approx(5.0 - surface_x)
    inside = np.array([[0.3, 0, 0]]) if kind == "ring" else np.zeros((1, 3))
    assert primitive_distance(inside, part)[0] < 0


def test_assemblies_are_closed_solids_that_pass_ingest_and_keep_a_boxs_faces_flat(tmp_path):
    settings = PrimitiveSettings()
    for k in range(2):
        parts = random_assembly(np.random.default_rng([3, k]), settings)
        assert 1 <= len(parts) <= settings.max_parts
        out, reason = assembly_mesh(parts, settings.resolution, "mid", 0.06, 5000)
        assert reason is None and out.is_watertight and np.sort(out.extents)[1] == pytest.approx(0.06)
        assert passes_ingest(out, tmp_path, f"asm{k}")["ok"]
    again, _ = assembly_mesh(random_assembly(np.random.default_rng([3, 1]), settings), 64, "mid", 0.06, 5000)
    assert np.array_equal(out.vertices, again.vertices)  # the same stream, the same assembly
    box = Primitive("box", np.array([0.2, 0.3, 0.5]), np.eye(3), np.zeros(3))
    mesh, _ = assembly_mesh([box], 64, "mid", 0.06, 100000)
    # a field sample, m: 64 across the box's bounding sphere (radius |size|), scaled by 0.06 / 0.6 m
    pitch, half = 0.1 * 2 * np.linalg.norm(box.size) / 64, mesh.extents / 2
    c = mesh.triangles_center - mesh.bounds.mean(axis=0)
    top = (c[:, 2] > half[2] - pitch) & (np.abs(c[:, :2]) < half[:2] - 2 * pitch).all(axis=1)  # away from the edges
    assert top.sum() > 10
    assert np.degrees(np.arccos(np.clip(mesh.face_normals[top, 2], -1, 1))).max() < 2.0
    assert np.allclose(np.sort(mesh.extents), [0.04, 0.06, 0.1], atol=pitch / 4)  # within 1/4 sample
    assert isinstance(mesh, trimesh.Trimesh)
