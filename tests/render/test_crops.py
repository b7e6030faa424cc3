"""Grasp crops: the ray-cast fast path against full 640×480 renders put through rotate/crop/resize."""

import numpy as np
import pytest
import trimesh

from graspaug.render.camera import sample_viewpoint
from graspaug.render.crops import CropGeometry, crops_by_ray_casting, crops_from_depth_image
from graspaug.render.depth import render_depth
from graspaug.render.pybullet_depth import PybulletDepthScene
from graspaug.render.settings import Intrinsics, ViewpointRanges
from graspaug.render.stable_poses import stable_poses

INTRINSICS = Intrinsics()


def test_crops_of_a_ramp_follow_the_jaw_direction():
    """An image whose depth grows along u: with the jaws along u (angle 0) the crop grows along
    its columns; with the jaws along v (angle pi/2) it falls along its rows."""
    v, u = np.mgrid[0:480, 0:640].astype(float)
    ramp = 0.5 + 0.001 * u
    geometry = CropGeometry(96, 32)
    center = np.array([[300.25, 200.5]])
    along = crops_from_depth_image(ramp, center, [0.0], geometry)[0]
    # block j covers crop columns 3j..3j+2 at u = 300.25 + c - 47.5; their mean is at c = 3j + 1
    expected = 0.5 + 0.001 * (300.25 + 3 * np.arange(32) + 1 - 47.5)
    np.testing.assert_allclose(along, np.tile(expected, (32, 1)), atol=1e-6)
    across = crops_from_depth_image(ramp, center, [np.pi / 2], geometry)[0]
    np.testing.assert_allclose(across, np.tile(expected[::-1, None], (1, 32)), atol=1e-6)
    np.testing.assert_allclose(crops_from_depth_image(ramp, center, [np.pi], geometry)[0], along[:, ::-1], atol=1e-6)


def _scenes(meshes, n_scenes, seed):
    """Random scenes: a mesh in a random stable pose, a random camera, grasps at random visible
    surface points with random jaw directions."""
    rng = np.random.default_rng(seed)
    scenes = []
    for k in range(n_scenes):
        mesh = meshes[k % len(meshes)]
        poses = stable_poses(mesh)
        pose = poses.transforms[rng.integers(min(3, len(poses)))]
        camera = sample_viewpoint(ViewpointRanges(), rng)
        placed = mesh.copy().apply_transform(pose)
        points, _ = trimesh.sample.sample_surface(placed, 8, seed=int(rng.integers(1 << 31)))
        centers = INTRINSICS.project(camera.to_camera(points))
        angles = rng.uniform(-np.pi, np.pi, len(points))
        scenes.append((mesh, pose, placed, camera, centers, angles))
    return scenes


@pytest.fixture(scope="module")
def scenes(duck, random_object):
    box = trimesh.creation.box((0.03, 0.05, 0.08))
    return _scenes([duck, random_object, box], 6, seed=0)


def test_ray_cast_crops_equal_full_ray_cast_image_crops(scenes):
    for mesh, pose, placed, camera, centers, angles in scenes:
        fast, n_rays = crops_by_ray_casting(mesh, camera, INTRINSICS, centers, angles, pose=pose)
        full = render_depth(placed, camera, INTRINSICS)
        reference = crops_from_depth_image(full, centers, angles)
        table_only = crops_from_depth_image(render_depth(None, camera, INTRINSICS), centers, angles)
        assert fast.shape == reference.shape == (8, 32, 32) and fast.dtype == np.float32
        diff = np.abs(fast - reference)
        assert diff.mean() <= 1e-3  # issue: <= 1 mm (embree's float32 may flip a silhouette pixel)
        table = np.abs(reference - table_only) < 1e-9
        assert table.any() and (~table).any()  # both object and table in the crops
        assert diff[table].max() <= 1e-4  # table pixels exact to 0.1 mm (they are analytic: < 1e-6)
        assert np.median(diff) < 1e-6
        assert 0 < n_rays < 0.1 * INTRINSICS.width * INTRINSICS.height  # far fewer rays than a full image


def test_ray_cast_crops_match_pybullet_tiny_renderer(scenes):
    """An independent reference: pybullet's rasterizer with our camera turned into OpenGL matrices."""
    from scipy import ndimage

    with PybulletDepthScene() as pybullet_scene:
        for mesh, pose, placed, camera, centers, angles in scenes:
            pybullet_scene.place(mesh, pose)
            reference = crops_from_depth_image(pybullet_scene.depth(camera, INTRINSICS), centers, angles)
            fast, _ = crops_by_ray_casting(mesh, camera, INTRINSICS, centers, angles, pose=pose)
            table_only = crops_from_depth_image(render_depth(None, camera, INTRINSICS), centers, angles)
            object_pixels = ndimage.binary_dilation(
                np.abs(fast - table_only) > 1e-9, structure=np.ones((1, 3, 3), bool)
            )
            diff = np.abs(fast - reference)
            assert diff.mean() <= 1e-3
            assert diff[~object_pixels].max() <= 1e-4


def test_no_grasps_and_a_camera_below_the_table(duck):
    camera = sample_viewpoint(ViewpointRanges(), np.random.default_rng(0))
    crops, rays = crops_by_ray_casting(duck, camera, INTRINSICS, np.zeros((0, 2)), np.zeros(0))
    assert crops.shape == (0, 32, 32) and rays == 0
    below = type(camera)(rotation=camera.rotation, position=camera.position * np.array([1, 1, -1]))
    with pytest.raises(ValueError, match="above the table"):
        crops_by_ray_casting(duck, below, INTRINSICS, np.zeros((1, 2)), np.zeros(1))
    with pytest.raises(ValueError, match="multiple"):
        CropGeometry(96, 40)
