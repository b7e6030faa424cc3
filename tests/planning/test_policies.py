"""The grasp policies: the cross-entropy method with a GQ-CNN and the random antipodal reference."""

from __future__ import annotations

import numpy as np
import torch

from graspaug.planning.grasps import distinct_grasps
from graspaug.planning.policies import CrossEntropyGraspPolicy, GraspPolicy, RandomAntipodalPolicy
from graspaug.planning.sampler import sample_antipodal_grasps
from graspaug.planning.settings import CEMSettings, SamplerSettings
from graspaug.render.settings import Intrinsics

K = Intrinsics()


class DepthPreferringNet(torch.nn.Module):
    """A stand-in quality function that only likes deep grasps: P = sigmoid(200 (z - 0.64))."""

    def success_probability(self, images, z):
        return torch.sigmoid(200 * (z - 0.64))


def test_cross_entropy_method_climbs_the_quality(box_image):
    depth = box_image()
    rng = np.random.default_rng(1)
    seeds = sample_antipodal_grasps(depth, K, SamplerSettings(), 100, np.random.default_rng(1))
    policy = CrossEntropyGraspPolicy(DepthPreferringNet(), K, cem=CEMSettings(num_seed_samples=100))
    ranked = policy.plan_ranked(depth, rng)
    assert ranked is not None
    grasps, quality, scored = ranked
    assert len(grasps) == 1 and 200 < scored <= 100 + 3 * 50  # GMM draws outside the image or too wide are dropped
    assert quality[0] >= np.quantile(policy.quality(depth, seeds), 0.9)
    assert grasps.depths[0] > 0.65  # deeper than most seeds (uniform in 0.625-0.66)
    assert 270 < grasps.centers[0, 0] < 330 and 210 < grasps.centers[0, 1] < 290


def test_top_grasps_are_ranked_and_accept_filters_them(box_image):
    depth = box_image()
    policy = CrossEntropyGraspPolicy(DepthPreferringNet(), K, cem=CEMSettings(num_seed_samples=100))
    grasps, quality, _ = policy.plan_ranked(depth, np.random.default_rng(2), top=5)
    # up to 5 distinct grasps: the last iteration's 50 draws cluster, near-duplicates are dropped
    assert 3 <= len(grasps) <= 5 and np.all(np.diff(quality) <= 0)
    assert distinct_grasps(grasps, 5).tolist() == list(range(len(grasps)))
    best, best_quality, _ = policy.plan_ranked(depth, np.random.default_rng(2), top=1)
    assert np.array_equal(best.centers, grasps.centers[:1]) and best_quality[0] == quality[0]
    everything = lambda g: np.ones(len(g), dtype=bool)  # noqa: E731
    assert len(policy.plan_ranked(depth, np.random.default_rng(2), top=5, accept=everything)[0]) == 5  # and the seeds
    assert policy.plan_ranked(depth, np.random.default_rng(2), accept=lambda g: np.zeros(len(g), dtype=bool)) is None


def test_random_policy_draws_seeds_without_quality(box_image):
    depth = box_image()
    policy = RandomAntipodalPolicy(K)
    grasps, quality, scored = policy.plan_ranked(depth, np.random.default_rng(0), top=3)
    assert len(grasps) == 3 and np.all(np.isnan(quality)) and scored == 3
    assert distinct_grasps(grasps, 3).tolist() == [0, 1, 2]
    one, _, _ = policy.plan_ranked(depth, np.random.default_rng(0), top=1)  # one seed drawn, as before
    first = sample_antipodal_grasps(depth, K, SamplerSettings(), 1, np.random.default_rng(0))
    assert np.array_equal(one.centers, first.centers) and np.array_equal(one.angles, first.angles)
    assert policy.plan_ranked(np.full((480, 640), 0.65), np.random.default_rng(0)) is None


def test_both_policies_are_grasp_policies():
    policies: list[GraspPolicy] = [RandomAntipodalPolicy(K), CrossEntropyGraspPolicy(DepthPreferringNet(), K)]
    for policy in policies:
        assert callable(policy.plan_ranked)
