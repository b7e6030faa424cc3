"""Stable poses: the same poses and probabilities as trimesh's reference implementation."""

import numpy as np
import pytest
import trimesh

from graspaug.render.stable_poses import stable_poses


def _as_dict(transforms, probabilities):
    """Pose → probability, keyed by the rounded table normal in the object frame (order-free:
    poses of equal probability may come in either order)."""
    return {tuple(np.round(t[2, :3], 6)): p for t, p in zip(transforms, probabilities)}


@pytest.mark.parametrize("name", ["box", "cylinder", "capsule", "random_object", "wedge"])
def test_same_poses_as_trimesh(name, random_object):
    meshes = {
        "box": trimesh.creation.box((0.03, 0.05, 0.07)),
        "cylinder": trimesh.creation.cylinder(0.02, 0.08, sections=24),
        "capsule": trimesh.creation.capsule(0.06, 0.015),
        "random_object": random_object,
        "wedge": trimesh.convex.convex_hull(
            np.array([[0, 0, 0], [0.08, 0, 0], [0, 0.03, 0], [0.08, 0.03, 0], [0, 0, 0.05], [0, 0.03, 0.05]], float)
        ),
    }
    mesh = meshes[name]
    expected_t, expected_p = trimesh.poses.compute_stable_poses(mesh)
    ours = stable_poses(mesh)
    assert len(ours) == len(expected_p)
    expected, got = _as_dict(expected_t, expected_p), _as_dict(ours.transforms, ours.probabilities)
    assert expected.keys() == got.keys()
    for key in expected:
        assert got[key] == pytest.approx(expected[key], abs=1e-12)
    for ours_t, key in zip(ours.transforms, got):  # same transform for the same pose
        match = next(t for t in expected_t if tuple(np.round(t[2, :3], 6)) == key)
        np.testing.assert_allclose(ours_t, match, atol=1e-12)
    assert np.all(np.diff(ours.probabilities) <= 0)  # most probable first


def test_a_box_rests_on_its_faces_with_the_larger_faces_likelier():
    mesh = trimesh.creation.box((0.02, 0.04, 0.08))
    poses = stable_poses(mesh)
    assert len(poses) == 6 and poses.probabilities.sum() == pytest.approx(1.0)
    heights = []
    for transform in poses.transforms:
        rested = mesh.copy().apply_transform(transform)
        assert rested.bounds[0, 2] == pytest.approx(0.0, abs=1e-12)  # touching the table
        np.testing.assert_allclose(rested.center_mass[:2], 0.0, atol=1e-12)  # center of mass above the origin
        heights.append(rested.extents[2])
    # lying flat (0.02 m tall) is likelier than on the side (0.04 m), likelier than upright (0.08 m)
    np.testing.assert_allclose(heights, [0.02, 0.02, 0.04, 0.04, 0.08, 0.08], atol=1e-12)
    assert poses.probabilities[0] == pytest.approx(poses.probabilities[1])
    assert poses.probabilities[1] > poses.probabilities[2] > poses.probabilities[4]


def test_a_cube_lands_on_each_face_equally_often():
    poses = stable_poses(trimesh.creation.box((0.05, 0.05, 0.05)))
    np.testing.assert_allclose(poses.probabilities, np.full(6, 1 / 6), atol=1e-12)
