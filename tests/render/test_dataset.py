"""One shape's datapoints: which grasps appear, their geometry, determinism."""

import numpy as np
import trimesh

from graspaug.grasping.gripper import ParallelJawGripper
from graspaug.render.dataset import RenderSettings, render_shape
from graspaug.render.stable_poses import stable_poses

HAND = ParallelJawGripper()


def box_grasps():
    """A 3 × 5 × 7 cm box and grasps through its center along each of its axes, plus tilted ones."""
    mesh = trimesh.creation.box((0.03, 0.05, 0.07))
    axes = np.array([[1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 0, 0.02], [1, 1, 1]], float)
    axes /= np.linalg.norm(axes, axis=1, keepdims=True)
    return mesh, np.zeros((len(axes), 3)), axes


def test_only_table_parallel_grasps_appear_and_their_geometry_is_consistent():
    mesh, centers, axes = box_grasps()
    settings = RenderSettings(max_poses=6, images_per_pose=2)
    data = render_shape(mesh, centers, axes, HAND, settings, np.random.default_rng(0))
    poses = stable_poses(mesh)
    assert data.n_poses == 6 and len(data) > 0
    assert data.images.shape == (len(data), 32, 32) and data.images.dtype == np.float32
    cols = data.columns
    for index, pose_id in zip(cols["grasp_index"], cols["pose_id"]):
        axis = poses.transforms[pose_id][:3, :3] @ axes[index]
        assert abs(axis[2]) <= np.sin(np.radians(5)) + 1e-12  # within 5 deg of the table
    assert 4 not in cols["grasp_index"]  # 35 deg off the table in every pose
    assert 3 in cols["grasp_index"]  # 1.1 deg off: kept
    # each pose shows the two grasps along its horizontal box axes (and the slightly tilted copy)
    assert set(np.unique(cols["pose_id"])) == set(range(6))
    assert np.all((cols["image_id"] // 2) == cols["pose_id"])
    # gripper depth: the grasp center is the box center, half the box height above the table
    for z, height, pose_id in zip(cols["z"], cols["camera_height"], cols["pose_id"]):
        half_height = poses.transforms[pose_id][2, 3]
        assert height - half_height - 0.11 <= z <= height - half_height + 0.011  # tilt <= 5 deg, offset <= 0.1 m
    assert np.all((cols["camera_tilt"] >= 0.1) & (cols["camera_tilt"] <= 5.0))
    # the object is under the crop center: nearer than the table around it
    center = data.images[:, 15:17, 15:17].mean(axis=(1, 2))
    corners = (
        np.concatenate([data.images[:, :2, :2], data.images[:, -2:, -2:]], axis=1).reshape(len(data), -1).max(axis=1)
    )
    assert np.all(center < corners - 0.01)
    # open jaws: 8 cm at ~0.7 m is ~60 px
    assert np.all((cols["width_px"] > 50) & (cols["width_px"] < 70))
    # through the center of a 3-7 cm box resting on the table, approached from above: the palm
    # clears the top and the fingertips stay above the table in every pose
    assert cols["collision_free"].dtype == bool
    for free, pose_id, index in zip(cols["collision_free"], cols["pose_id"], cols["grasp_index"]):
        width_across = np.abs(np.diag(np.ones(3)) @ axes[index]) @ np.array([0.03, 0.05, 0.07])
        assert free == (width_across < HAND.max_width)


def test_same_seed_same_datapoints_and_grasp_caps():
    mesh, centers, axes = box_grasps()
    first = render_shape(mesh, centers, axes, HAND, RenderSettings(), np.random.default_rng(5))
    again = render_shape(mesh, centers, axes, HAND, RenderSettings(), np.random.default_rng(5))
    np.testing.assert_array_equal(first.images, again.images)
    for name in first.columns:
        np.testing.assert_array_equal(first.columns[name], again.columns[name])
    other = render_shape(mesh, centers, axes, HAND, RenderSettings(), np.random.default_rng(6))
    assert not np.array_equal(other.columns["camera_height"], first.columns["camera_height"])
    capped = render_shape(
        mesh, centers, axes, HAND, RenderSettings(max_grasps_per_image=1, max_poses=2), np.random.default_rng(5)
    )
    assert np.all(np.bincount(capped.columns["image_id"]) <= 1) and capped.n_poses == 2


def test_no_grasps_or_no_table_parallel_grasp_gives_no_datapoints():
    mesh, centers, axes = box_grasps()
    empty = render_shape(mesh, centers[:0], axes[:0], HAND, RenderSettings(), np.random.default_rng(0))
    assert len(empty) == 0 and empty.images.shape == (0, 32, 32)
    upright = render_shape(mesh, centers[4:], axes[4:], HAND, RenderSettings(), np.random.default_rng(0))
    assert len(upright) == 0 and upright.n_poses == 5  # max_poses
    assert set(upright.columns) == set(empty.columns)


def test_crops_that_would_leave_the_image_are_not_rendered():
    from graspaug.render.dataset import crop_inside_image, plan_scenes
    from graspaug.render.settings import ViewpointRanges

    mesh, centers, axes = box_grasps()
    settings = RenderSettings(max_poses=6, images_per_pose=40, viewpoints=ViewpointRanges(object_offset=0.3))
    scenes, _ = plan_scenes(mesh, centers, axes, HAND.max_width, settings, np.random.default_rng(0))
    shown = sum(len(s.grasp_index) for s in scenes)
    centered = RenderSettings(max_poses=6, images_per_pose=40, viewpoints=ViewpointRanges(object_offset=0.0))
    all_shown = sum(
        len(s.grasp_index)
        for s in plan_scenes(mesh, centers, axes, HAND.max_width, centered, np.random.default_rng(0))[0]
    )
    # with the object up to 0.3 m off the image center, many crops would cross the border
    assert 0 < shown < 0.9 * all_shown
    for scene in scenes:
        u, v, angle = scene.image["center_u"], scene.image["center_v"], scene.image["angle"]
        assert crop_inside_image(u, v, angle, settings.crop, settings.intrinsics).all()
        reach = 47.5 * (np.abs(np.cos(angle)) + np.abs(np.sin(angle)))
        assert np.all((u - reach >= 0) & (u + reach <= 639) & (v - reach >= 0) & (v + reach <= 479))


def test_a_ball_gets_datapoints():
    """A ball has no stable pose the solver gives above Dex-Net's 0.01 (it rests in any orientation): it is
    rendered in uniformly drawn orientations instead of being skipped with '0 stable poses'."""
    ball = trimesh.creation.icosphere(3, 0.025)
    axes = np.random.default_rng(0).normal(size=(200, 3))
    axes /= np.linalg.norm(axes, axis=1, keepdims=True)
    data = render_shape(ball, np.zeros((200, 3)), axes, HAND, RenderSettings(), np.random.default_rng(0))
    assert data.n_poses == RenderSettings().max_poses and len(data) > 0
    assert len(np.unique(data.columns["pose_id"])) > 1
