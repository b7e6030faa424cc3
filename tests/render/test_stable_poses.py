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


def test_a_ball_rests_in_any_orientation_each_as_likely():
    """An icosphere's hull spreads its landing probability over 1,280 facets, none above 0.001, so the solver
    alone leaves it no pose Dex-Net keeps (>= 0.01): it gets N_ROUND orientations drawn uniformly, equally likely,
    the same ones every time (the stages that recompute poses number them alike), each resting on the table."""
    from graspaug.render.stable_poses import N_ROUND, ROUND_PROBABILITY, round_poses

    ball = trimesh.creation.icosphere(3, 0.03)
    poses = stable_poses(ball)
    assert poses.round and len(poses) == N_ROUND and np.all(poses.probabilities >= ROUND_PROBABILITY)
    np.testing.assert_allclose(poses.probabilities, 1 / N_ROUND)
    np.testing.assert_array_equal(poses.transforms, stable_poses(ball).transforms)  # deterministic from the seed
    assert not np.array_equal(poses.transforms, stable_poses(ball, seed=1).transforms)
    for transform in poses.transforms:
        rested = ball.copy().apply_transform(transform)
        assert rested.bounds[0, 2] == pytest.approx(0.0, abs=1e-12)
        np.testing.assert_allclose(rested.center_mass[:2], 0.0, atol=1e-9)
        np.testing.assert_allclose(transform[:3, :3] @ transform[:3, :3].T, np.eye(3), atol=1e-12)
    # uniform over rotations: the table normal in the object frame averages to 0, its squares to 1/3
    up = round_poses(ball.convex_hull, 4000, seed=0).transforms[:, 2, :3]
    np.testing.assert_allclose(up.mean(axis=0), 0.0, atol=0.05)
    np.testing.assert_allclose((up**2).mean(axis=0), 1 / 3, atol=0.03)
    assert not stable_poses(trimesh.creation.box((0.05, 0.05, 0.05))).round  # a cube keeps its six faces
