"""Antipodal seeds on the depth edges of an image, and the image test of a grasp."""

from __future__ import annotations

import math

import numpy as np

from graspaug.planning.grasps import ImageGrasps
from graspaug.planning.sampler import antipodal_in_image, depth_edges, sample_antipodal_grasps
from graspaug.planning.settings import SamplerSettings
from graspaug.render.settings import Intrinsics

K = Intrinsics()


def test_antipodal_seeds_on_a_box_are_straight_across_it(box_image):
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
    centers = grasps.centers
    assert np.all((centers[:, 0] > 278) & (centers[:, 0] < 322) & (centers[:, 1] > 218) & (centers[:, 1] < 282))
    # depth below the box top by 0.005-0.04 m
    assert np.all(grasps.depths >= 0.62 + 0.005 - 1e-9) and np.all(grasps.depths <= 0.62 + 0.04 + 1e-9)


def test_no_edges_no_grasps_and_border_edges_are_ignored(box_image):
    rng = np.random.default_rng(0)
    assert len(sample_antipodal_grasps(np.full((480, 640), 0.65), K, SamplerSettings(), 100, rng)) == 0
    near_border = box_image(box=(0, 0, 40, 480))  # only edge is at u = 40 (< 45 px from the border)
    assert len(sample_antipodal_grasps(near_border, K, SamplerSettings(), 100, rng)) == 0


def test_too_wide_for_the_gripper_gives_no_grasps(box_image):
    # 0.08 m at 0.62 m is 68 px: a 100 × 120 px box cannot be grasped across
    grasps = sample_antipodal_grasps(
        box_image(box=(270, 180, 370, 300)), K, SamplerSettings(), 100, np.random.default_rng(0)
    )
    assert len(grasps) == 0


def test_depth_edges_are_unit_normals_toward_the_farther_side(box_image):
    depth = box_image()
    edges, normals = depth_edges(depth, SamplerSettings().depth_grad_thresh)
    assert edges.shape == depth.shape and normals.shape == depth.shape + (2,)
    assert edges[250, 279] and edges[250, 280] and not edges[250, 300] and not edges[100, 100]
    assert np.allclose(np.linalg.norm(normals[edges], axis=1), 1.0) and not normals[~edges].any()
    assert np.allclose(normals[250, 279], [-1.0, 0.0]) and np.allclose(normals[250, 320], [1.0, 0.0])  # outward
    grad_v, grad_u = np.gradient(depth)
    v, u = np.nonzero(edges)
    expected = np.stack([grad_u[v, u], grad_v[v, u]], axis=1) / np.hypot(grad_u, grad_v)[v, u, None]
    assert np.array_equal(normals[v, u], expected)  # the sampler's arithmetic, bit for bit


def test_the_image_test_accepts_the_seeds_and_rejects_a_grasp_off_the_edges(box_image):
    depth = box_image()
    settings = SamplerSettings()
    seeds = sample_antipodal_grasps(depth, K, settings, 100, np.random.default_rng(0))
    assert antipodal_in_image(depth, seeds, settings).mean() > 0.5
    inside = ImageGrasps(np.array([[300.0, 250.0]]), np.array([0.0]), np.array([0.63]), np.array([10.0]))
    assert not antipodal_in_image(depth, inside, settings)[0]  # both jaws on the flat top
