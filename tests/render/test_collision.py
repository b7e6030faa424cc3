"""Approach collisions of the Panda's fingers and palm with the object and the table."""

import numpy as np
import pytest
import trimesh

from graspaug.grasping.gripper import ParallelJawGripper
from graspaug.render.collision import CollisionChecker, approach_directions

HAND = ParallelJawGripper()
DOWN = np.array([[0.0, 0.0, -1.0]])
ALONG_X = np.array([[1.0, 0.0, 0.0]])


def resting(extents):
    """A box centered at the origin and the pose that puts it on the table."""
    pose = np.eye(4)
    pose[2, 3] = extents[2] / 2
    return trimesh.creation.box(extents), pose


def free(mesh, pose, center, axis=ALONG_X):
    return bool(
        CollisionChecker(mesh, HAND).collision_free(np.atleast_2d(center), axis, approach_directions(axis), pose=pose)[
            0
        ]
    )


def test_a_small_cube_grasped_at_mid_height_is_reachable():
    mesh, pose = resting((0.04, 0.04, 0.04))
    assert free(mesh, pose, [0.0, 0.0, 0.02])
    assert free(mesh, pose, [0.0, 0.3, 0.05])  # empty space next to it


def test_fingertips_below_the_table_collide():
    mesh, pose = resting((0.04, 0.04, 0.04))
    # the fingertips reach 7.2 mm past the grasp center
    assert not free(mesh, pose, [0.0, 0.0, 0.005])
    assert free(mesh, pose, [0.0, 0.0, 0.009])


def test_an_object_wider_than_the_opening_blocks_the_fingers():
    mesh, pose = resting((0.1, 0.04, 0.04))
    assert not free(mesh, pose, [0.0, 0.0, 0.02])  # across the 0.1 m side: fingers land on top
    assert free(mesh, pose, [0.0, 0.0, 0.02], axis=np.array([[0.0, 1.0, 0.0]]))  # across the 0.04 m side


def test_the_palm_hits_a_tall_object_grasped_low():
    mesh, pose = resting((0.04, 0.04, 0.12))
    assert not free(mesh, pose, [0.0, 0.0, 0.03])  # palm 3.9 cm above the center, object 12 cm tall
    assert free(mesh, pose, [0.0, 0.0, 0.1])


def test_the_palm_keeps_its_clearance_above_the_object():
    """A 5 cm box grasped 1.5 cm below its top: the palm (3.9 cm behind the center) ends 2.4 cm above it. Grasped
    3.8 cm below its top the palm ends 1 mm above it: free without a clearance, not with 2 mm."""
    mesh, pose = resting((0.04, 0.04, 0.05))
    axis = ALONG_X

    def free_with(clearance, center):
        checker = CollisionChecker(mesh, HAND, 0.1, palm_clearance=clearance)
        return bool(checker.collision_free(np.array([center]), axis, approach_directions(axis), pose=pose)[0])

    assert free_with(0.0, [0, 0, 0.035]) and free_with(0.002, [0, 0, 0.035])
    assert free_with(0.0, [0, 0, 0.012]) and not free_with(0.002, [0, 0, 0.012])
    with pytest.raises(ValueError, match="palm_clearance"):
        CollisionChecker(mesh, HAND, 0.1, palm_clearance=-0.001)


def test_placing_by_pose_equals_moving_the_mesh(random_object):
    rng = np.random.default_rng(0)
    axes = rng.normal(size=(60, 3))
    axes[:, 2] *= 0.05
    axes /= np.linalg.norm(axes, axis=1, keepdims=True)
    approaches = approach_directions(axes)
    np.testing.assert_allclose(np.einsum("ij,ij->i", approaches, axes), 0, atol=1e-12)
    np.testing.assert_allclose(np.linalg.norm(approaches, axis=1), 1, atol=1e-12)
    np.testing.assert_allclose(
        approaches[:, 2], -np.sqrt(1 - axes[:, 2] ** 2), atol=1e-12
    )  # as steep as the axis allows
    pose = trimesh.transformations.random_rotation_matrix(rng.random(3))
    moved = random_object.copy().apply_transform(pose)
    pose[2, 3] = -moved.bounds[0, 2]  # on the table
    moved.apply_translation([0, 0, pose[2, 3]])
    centers = rng.uniform(moved.bounds[0], moved.bounds[1], size=(60, 3))
    by_pose = CollisionChecker(random_object, HAND).collision_free(centers, axes, approaches, pose=pose)
    by_moving = CollisionChecker(moved, HAND).collision_free(centers, axes, approaches)
    np.testing.assert_array_equal(by_pose, by_moving)
    assert by_pose.any() and (~by_pose).any()


def test_negative_approach_distance_is_an_error(random_object):
    with pytest.raises(ValueError, match="approach_distance"):
        CollisionChecker(random_object, HAND, approach_distance=-0.1)
