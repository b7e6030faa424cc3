"""The antipodal sampler on real closed meshes: every grasp it returns passes Dex-Net's tests."""

import dataclasses

import numpy as np
import pytest
import trimesh

from graspaug.geometry.prepare import SurfaceSettings, prepare_shape
from graspaug.grasping.antipodal import AntipodalSettings, force_closure, sample_antipodal_grasps
from graspaug.grasping.contacts import close_fingers
from graspaug.grasping.gripper import ParallelJawGripper

SETTINGS = AntipodalSettings(
    n_grasps=40,
    friction_coef=0.5,
    tries_per_point=2,
    oversample=5,
    max_rounds=5,
    max_surface_points=100,
    min_contact_dist=0.0025,
    coverage_dist=0.0025,
)
PANDA = ParallelJawGripper()


@pytest.fixture(scope="module")
def default_meshes(default_loaded):
    """Closed outer surfaces of two default objects, as ingest makes them."""
    settings = SurfaceSettings()
    return [prepare_shape(loaded, settings).mesh for _, loaded in default_loaded[:2]]


def on_surface(mesh, points, tol=1e-9):
    """(N,) bool: the point lies in some triangle (plane distance and barycentric coordinates
    within ``tol``), checked against every triangle."""
    tris = np.repeat(mesh.triangles[None], len(points), axis=0).reshape(-1, 3, 3)
    pts = np.repeat(points, len(mesh.faces), axis=0)
    normals = np.repeat(mesh.face_normals[None], len(points), axis=0).reshape(-1, 3)
    height = np.abs(np.einsum("ij,ij->i", pts - tris[:, 0], normals))
    bary = trimesh.triangles.points_to_barycentric(tris, pts)
    inside = (height < tol) & (bary.min(axis=1) > -tol)
    return inside.reshape(len(points), -1).any(axis=1)


def check_grasps(mesh, grasps, settings, gripper):
    assert 0 < len(grasps) <= settings.n_grasps
    np.testing.assert_allclose(np.linalg.norm(grasps.axis, axis=1), 1.0, atol=1e-12)
    line = grasps.p2 - grasps.p1
    width = np.linalg.norm(line, axis=1)
    assert np.all(width >= settings.min_contact_dist) and np.all(width <= gripper.max_width)
    # force closure, measured: both inward normals within atan(μ) of the contact line
    for normal, direction in ((-grasps.n1, line), (-grasps.n2, -line)):
        angle = np.degrees(np.arccos(np.clip(np.einsum("ij,ij->i", normal, direction) / width, -1, 1)))
        assert angle.max() <= np.degrees(np.arctan(settings.friction_coef)) + 1e-9
    # the contacts lie on the grasp axis, jaw 1 before jaw 2
    np.testing.assert_allclose(line / width[:, None], grasps.axis, atol=1e-9)
    for p in (grasps.p1, grasps.p2):  # contacts lie on the surface
        assert on_surface(mesh, p).all()
    # the jaws closing on the grasp's center and axis find exactly these contacts
    again = close_fingers(mesh, grasps.center, grasps.axis, gripper.max_width)
    assert again.found.all()
    np.testing.assert_allclose(again.p1, grasps.p1, atol=1e-12)
    np.testing.assert_allclose(again.p2, grasps.p2, atol=1e-12)
    np.testing.assert_allclose(again.n2, grasps.n2, atol=1e-12)
    if settings.coverage_dist > 0:
        d = np.linalg.norm(grasps.center[:, None] - grasps.center[None], axis=2)
        assert d[np.triu_indices(len(d), 1)].min() >= settings.coverage_dist


def test_grasps_on_default_objects_pass_every_test(default_meshes):
    for mesh in default_meshes:
        grasps = sample_antipodal_grasps(mesh, PANDA, SETTINGS, np.random.default_rng(0))
        assert len(grasps) == SETTINGS.n_grasps
        check_grasps(mesh, grasps, SETTINGS, PANDA)


def test_axes_lie_in_the_friction_cone_of_a_sphere():
    mesh = trimesh.creation.icosphere(subdivisions=4, radius=0.03)
    grasps = sample_antipodal_grasps(mesh, PANDA, SETTINGS, np.random.default_rng(1))
    check_grasps(mesh, grasps, SETTINGS, PANDA)
    # on a sphere the axis is the chord between the contacts: its angle to the inward normal
    # is at most atan(μ)
    cos = np.einsum("ij,ij->i", grasps.axis, -grasps.n1)
    assert np.degrees(np.arccos(cos)).max() <= np.degrees(np.arctan(0.5)) + 1e-6
    assert np.degrees(np.arccos(cos)).max() > 10  # and they do spread inside it


def test_same_seed_same_grasps_other_seed_other_grasps(default_meshes):
    mesh = default_meshes[0]
    a = sample_antipodal_grasps(mesh, PANDA, SETTINGS, np.random.default_rng(5))
    b = sample_antipodal_grasps(mesh, PANDA, SETTINGS, np.random.default_rng(5))
    c = sample_antipodal_grasps(mesh, PANDA, SETTINGS, np.random.default_rng(6))
    np.testing.assert_array_equal(a.center, b.center)
    assert not np.array_equal(a.center, c.center)


def test_object_wider_than_the_gripper_gives_no_grasps():
    mesh = trimesh.creation.box((0.1, 0.12, 0.09))
    grasps = sample_antipodal_grasps(mesh, PANDA, SETTINGS, np.random.default_rng(0))
    assert len(grasps) == 0 and grasps.center.shape == (0, 3)


def test_narrow_gripper_and_no_coverage_rejection():
    mesh = trimesh.creation.box((0.02, 0.05, 0.06))
    narrow = ParallelJawGripper(max_width=0.03)
    settings = dataclasses.replace(SETTINGS, n_grasps=25, coverage_dist=0.0)
    grasps = sample_antipodal_grasps(mesh, narrow, settings, np.random.default_rng(0))
    check_grasps(mesh, grasps, settings, narrow)
    # only across the 2 cm side, at most atan(μ) off its normal
    assert grasps.width.min() >= 0.02 - 1e-9 and grasps.width.max() <= 0.02 / np.cos(np.arctan(0.5)) + 1e-9


def test_gripper_rejects_impossible_widths():
    with pytest.raises(ValueError, match="min_width < max_width"):
        ParallelJawGripper(max_width=0.02, min_width=0.03)


def test_force_closure_test_by_hand():
    """Contacts on the x axis; contact 2's normal tilted by 20 deg (inside atan 0.5 = 26.6)
    or 30 deg (outside)."""
    p1, p2, n1 = np.array([[0.0, 0, 0]]), np.array([[0.02, 0, 0]]), np.array([[-1.0, 0, 0]])
    for degrees, expected in ((20, True), (30, False)):
        a = np.radians(degrees)
        n2 = np.array([[np.cos(a), np.sin(a), 0.0]])
        assert force_closure(p1, n1, p2, n2, 0.5)[0] == expected
