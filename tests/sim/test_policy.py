"""The depth-image grasp policy: antipodal seeds, the cross-entropy method, image → table frame."""
from __future__ import annotations

import math

import numpy as np
import torch

from graspaug.render.camera import Intrinsics, look_at
from graspaug.sim.policy import (
    CEMSettings, CrossEntropyGraspPolicy, ImageGrasps, SamplerSettings, grasp_features, grasp_in_table_frame, grasps_from_features,
    sample_antipodal_grasps,
)

K = Intrinsics()


def box_image(top: float = 0.62, box=(280, 220, 320, 280), table: float = 0.65) -> np.ndarray:
    """A flat table with a box seen from above: columns u0..u1 (40 px), rows v0..v1 (60 px)."""
    depth = np.full((480, 640), table)
    u0, v0, u1, v1 = box
    depth[v0:v1, u0:u1] = top
    return depth


def test_antipodal_seeds_on_a_box_are_straight_across_it():
    settings = SamplerSettings()
    grasps = sample_antipodal_grasps(box_image(), K, settings, 200, np.random.default_rng(0))
    assert 50 <= len(grasps) <= 200
    # friction cone atan(0.8) = 38.7 deg around the normals of the box's sides: across the short
    # side (u, width ~40 px) or the long side (v, ~60 px), within the cone
    cone = math.atan(0.8)
    across_u = np.abs(grasps.angles) <= cone + 1e-9
    across_v = np.abs(np.abs(grasps.angles) - np.pi / 2) <= cone + 1e-9
    assert np.all(across_u | across_v)
    assert np.all(grasps.widths[across_u] >= 38) and np.all(grasps.widths[across_u] <= 40 / math.cos(cone) + 3)
    assert np.all((grasps.centers[:, 0] > 278) & (grasps.centers[:, 0] < 322) & (grasps.centers[:, 1] > 218) & (grasps.centers[:, 1] < 282))
    # depth below the box top by 0.005-0.04 m
    assert np.all(grasps.depths >= 0.62 + 0.005 - 1e-9) and np.all(grasps.depths <= 0.62 + 0.04 + 1e-9)


def test_no_edges_no_grasps_and_border_edges_are_ignored():
    rng = np.random.default_rng(0)
    assert len(sample_antipodal_grasps(np.full((480, 640), 0.65), K, SamplerSettings(), 100, rng)) == 0
    near_border = box_image(box=(0, 0, 40, 480))  # only edge is at u = 40 (< 45 px from the border)
    assert len(sample_antipodal_grasps(near_border, K, SamplerSettings(), 100, rng)) == 0


def test_too_wide_for_the_gripper_gives_no_grasps():
    # 0.08 m at 0.62 m is 68 px: a 100 × 120 px box cannot be grasped across
    grasps = sample_antipodal_grasps(box_image(box=(270, 180, 370, 300)), K, SamplerSettings(), 100, np.random.default_rng(0))
    assert len(grasps) == 0


def test_features_round_trip():
    grasps = ImageGrasps(centers=np.array([[300.0, 200.0], [100.5, 50.0]]), angles=np.array([0.3, -1.2]), depths=np.array([0.61, 0.63]),
                         widths=np.array([40.0, 22.0]))
    back = grasps_from_features(grasp_features(grasps))
    for name in ("centers", "angles", "depths", "widths"):
        assert np.allclose(getattr(back, name), getattr(grasps, name))


class DepthPreferringNet(torch.nn.Module):
    """A stand-in quality function that only likes deep grasps: P = sigmoid(200 (z - 0.64))."""

    def success_probability(self, images, z):
        return torch.sigmoid(200 * (z - 0.64))


def test_cross_entropy_method_climbs_the_quality():
    depth = box_image()
    rng = np.random.default_rng(1)
    seeds = sample_antipodal_grasps(depth, K, SamplerSettings(), 100, np.random.default_rng(1))
    policy = CrossEntropyGraspPolicy(DepthPreferringNet(), K, cem=CEMSettings(num_seed_samples=100))
    planned = policy.plan(depth, rng)
    assert planned is not None and 200 < planned.candidates <= 100 + 3 * 50  # GMM draws outside the image or too wide are dropped
    assert planned.quality >= np.quantile(policy.quality(depth, seeds), 0.9)
    assert planned.grasp.depths[0] > 0.65  # deeper than most seeds (uniform in 0.625-0.66)
    assert 270 < planned.grasp.centers[0, 0] < 330 and 210 < planned.grasp.centers[0, 1] < 290


def test_image_grasp_to_table_frame():
    camera = look_at(np.array([0.0, 0.0, 0.65]), np.zeros(3))
    point = np.array([[0.05, -0.03, 0.02]])
    uv = K.project(camera.to_camera(point))
    grasps = ImageGrasps(centers=uv, angles=np.array([0.4]), depths=np.array([0.63]), widths=np.array([30.0]))
    centers, angles = grasp_in_table_frame(grasps, camera, K)
    assert np.allclose(centers, point, atol=1e-9)
    # seen from above the image's u axis is the table's x axis and v is -y: image angle a is table angle -a
    assert np.isclose(angles[0], -0.4)
