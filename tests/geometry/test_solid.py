import numpy as np
import pytest
import trimesh

from graspaug.geometry.solid import convex_part, outer_surface_of_parts, union_contains


def box_part(lo, hi):
    return convex_part(trimesh.creation.box(bounds=np.array([lo, hi])).vertices)


def test_half_spaces_agree_with_contains_on_a_convex_body():
    mesh = trimesh.creation.icosphere(subdivisions=2, radius=0.03)
    part = convex_part(mesh.vertices)
    pts = np.random.default_rng(0).uniform(-0.035, 0.035, (4000, 3))
    assert np.array_equal(union_contains([part], pts), mesh.contains(pts))


def test_flat_point_sets_have_no_part():
    assert convex_part(np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]], float)) is None
    assert convex_part(np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], float)) is None


def test_scaled_part_is_the_scaled_solid():
    part = box_part([0, 0, 0], [0.02, 0.03, 0.04])
    moved = part.scaled(2.0, np.array([0.1, 0.0, -0.1]))
    pts = np.random.default_rng(1).uniform(-0.2, 0.2, (5000, 3))
    assert np.array_equal(union_contains([moved], pts), union_contains([part], (pts - [0.1, 0.0, -0.1]) / 2.0))


def test_touching_boxes_become_one_closed_piece_with_their_volume():
    parts = [box_part([0, 0, 0], [0.03, 0.02, 0.02]), box_part([0.03, 0, 0], [0.05, 0.02, 0.04])]
    mesh, dropped = outer_surface_of_parts(parts, resolution=64, face_budget=2000)
    assert mesh.is_watertight and mesh.body_count == 1 and dropped == 0
    assert mesh.volume == pytest.approx(0.03 * 0.02 * 0.02 + 0.02 * 0.02 * 0.04, rel=0.02)
    assert len(mesh.faces) <= 2000


def test_a_hair_gap_is_closed_but_a_real_gap_is_not():
    a = box_part([0, 0, 0], [0.03, 0.02, 0.02])
    near = box_part([0.0301, 0, 0], [0.05, 0.02, 0.02])  # 0.1 mm gap, as in some default objects
    far = box_part([0.04, 0, 0], [0.05, 0.02, 0.02])  # 10 mm gap
    mesh, dropped = outer_surface_of_parts([a, near], resolution=96, face_budget=4000)
    assert mesh.body_count == 1 and dropped == 0
    mesh, dropped = outer_surface_of_parts([a, far], resolution=96, face_budget=4000)
    assert dropped == pytest.approx(0.25, abs=0.02)  # the small box is a separate piece


# 26 unit directions: the axes, face diagonals and body diagonals of a cube
_DIRS = np.array(
    [(i, j, k) for i in (-1, 0, 1) for j in (-1, 0, 1) for k in (-1, 0, 1) if (i, j, k) != (0, 0, 0)], float
)
_DIRS /= np.linalg.norm(_DIRS, axis=1, keepdims=True)


def _inner_hits(mesh: trimesh.Trimesh, parts, rng, n_rays=400, radius=2e-3) -> tuple[int, int]:
    """Cast rays through the object; count the hits that lie deep inside the true solid (all 26
    points at ``radius`` around the hit are inside the union of parts: a face inside the solid),
    and all hits. ``radius`` exceeds the rebuilt surface's error (about one 1 mm field cell)."""
    center = mesh.bounds.mean(axis=0)
    reach = np.linalg.norm(mesh.extents)
    direction = rng.normal(size=(n_rays, 3))
    direction /= np.linalg.norm(direction, axis=1, keepdims=True)
    target = center + rng.uniform(-0.3, 0.3, (n_rays, 3)) * mesh.extents
    origins = target - direction * reach
    locations, _, _ = mesh.ray.intersects_location(origins, direction, multiple_hits=True)
    around = (locations[:, None, :] + radius * _DIRS[None]).reshape(-1, 3)
    deep = union_contains(parts, around).reshape(len(locations), len(_DIRS)).all(axis=1)
    return int(deep.sum()), len(locations)


def test_rays_only_hit_the_outer_surface(default_loaded):
    """On the rebuilt surface no ray ever stops on an inner face; on the raw assembly of
    convex parts many do (so the check can fail)."""
    rng = np.random.default_rng(0)
    raw_inner = 0
    for _, loaded in default_loaded:
        mesh, _ = outer_surface_of_parts(loaded.parts, resolution=96, face_budget=5000)
        inner, total = _inner_hits(mesh, loaded.parts, rng)
        assert total > 100
        assert inner == 0
        raw_inner += _inner_hits(loaded.mesh, loaded.parts, rng)[0]
    assert raw_inner > 20


def test_rebuilt_default_shapes_are_closed_one_piece_and_parity_is_even(default_loaded):
    rng = np.random.default_rng(1)
    for _, loaded in default_loaded:
        mesh, dropped = outer_surface_of_parts(loaded.parts, resolution=96, face_budget=5000)
        assert mesh.is_watertight and mesh.body_count == 1 and mesh.is_winding_consistent
        assert mesh.volume > 0 and dropped < 0.01
        origins = mesh.bounds[0] - 0.01 + rng.uniform(0, 1, (200, 3)) * (mesh.extents + 0.02) * [1, 1, 0]
        _, ray_idx, _ = mesh.ray.intersects_location(origins, np.tile([0, 0, 1.0], (200, 1)), multiple_hits=True)
        assert np.all(np.bincount(ray_idx, minlength=200) % 2 == 0)
