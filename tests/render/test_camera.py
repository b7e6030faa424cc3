"""Pinhole cameras: projection, frames, Dex-Net's random viewpoints."""

import numpy as np
import pytest

from graspaug.render.camera import look_at, sample_viewpoint
from graspaug.render.settings import Intrinsics, ViewpointRanges


def test_a_camera_straight_above_sees_its_target_at_the_principal_point():
    camera = look_at([0.0, 0.0, 0.7], [0.0, 0.0, 0.0])
    intrinsics = Intrinsics()
    np.testing.assert_allclose(camera.rotation[:, 2], [0, 0, -1], atol=1e-12)
    assert camera.height == pytest.approx(0.7) and camera.tilt == pytest.approx(0.0, abs=1e-9)
    uv = intrinsics.project(camera.to_camera(np.array([[0.0, 0.0, 0.0], [0.01, 0.0, 0.0]])))
    np.testing.assert_allclose(uv[0], [319.5, 239.5], atol=1e-9)
    # 1 cm along the table's x at 0.7 m: 525 * 0.01 / 0.7 = 7.5 px along the image's u (roll 0)
    np.testing.assert_allclose(uv[1] - uv[0], [7.5, 0.0], atol=1e-9)


def test_projection_and_rays_invert_each_other_and_frames_compose():
    rng = np.random.default_rng(0)
    intrinsics = Intrinsics(width=600, height=400, fx=520.0, fy=530.0, cx=301.0, cy=198.0)
    points = rng.uniform([-0.2, -0.2, 0.5], [0.2, 0.2, 0.9], size=(50, 3))
    uv = intrinsics.project(points)
    np.testing.assert_allclose(intrinsics.rays(uv[:, 0], uv[:, 1]) * points[:, 2:], points, atol=1e-12)
    camera = look_at([0.05, -0.03, 0.7], [0.01, 0.02, 0.0], roll=0.7)
    np.testing.assert_allclose(camera.to_table(camera.to_camera(points)), points, atol=1e-12)
    angle = 0.4
    pose = np.eye(4)
    pose[:3, :3] = [[np.cos(angle), -np.sin(angle), 0], [np.sin(angle), np.cos(angle), 0], [0, 0, 1]]
    pose[:3, 3] = [0.02, -0.01, 0.03]
    in_object = rng.normal(scale=0.03, size=(20, 3))
    in_table = in_object @ pose[:3, :3].T + pose[:3, 3]
    np.testing.assert_allclose(camera.in_frame(pose).to_camera(in_object), camera.to_camera(in_table), atol=1e-12)


def test_random_viewpoints_stay_in_their_ranges_and_see_the_object():
    ranges = ViewpointRanges(distance=(0.65, 0.75), tilt_deg=(0.1, 5.0), object_offset=0.1)
    rng = np.random.default_rng(1)
    intrinsics = Intrinsics()
    tilts, rolls = [], []
    for _ in range(300):
        camera = sample_viewpoint(ranges, rng)
        axis = camera.rotation[:, 2]
        target = camera.position - axis * camera.position[2] / axis[2]  # where the optical axis meets the table
        assert 0.65 - 1e-9 <= np.linalg.norm(camera.position - target) <= 0.75 + 1e-9
        assert np.all(np.abs(target[:2]) <= 0.1 + 1e-9) and abs(target[2]) < 1e-12
        tilts.append(np.degrees(camera.tilt))
        rolls.append(np.arctan2(camera.rotation[1, 0], camera.rotation[0, 0]))
        u, v = intrinsics.project(camera.to_camera(np.zeros((1, 3))))[0]
        assert 0 <= u < 640 and 0 <= v < 480  # the object (at the origin) is in the image
        np.testing.assert_allclose(camera.rotation.T @ camera.rotation, np.eye(3), atol=1e-12)
        assert np.linalg.det(camera.rotation) == pytest.approx(1.0)
    assert 0.1 - 1e-9 <= min(tilts) and max(tilts) <= 5.0 + 1e-9 and max(tilts) - min(tilts) > 4
    assert np.ptp(rolls) > 5  # rolls cover the circle
    with pytest.raises(ValueError, match="tilt"):
        ViewpointRanges(tilt_deg=(5.0, 1.0))
