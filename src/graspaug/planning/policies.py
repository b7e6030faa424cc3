"""Grasp policies on a depth image: Dex-Net 2.0's cross-entropy method with a GQ-CNN
(``CrossEntropyRobustGraspingPolicy``), and a random antipodal grasp without a network.

The crops the GQ-CNN scores are the same 96 → 32 crops the training data has
(:func:`graspaug.render.crops.crops_from_depth_image`).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Protocol

import numpy as np
import torch
from sklearn.mixture import GaussianMixture

from graspaug.nets.gqcnn import GQCNN, GQCNNEnsemble
from graspaug.planning.grasps import ImageGrasps, distinct_grasps, grasp_features, grasps_from_features
from graspaug.planning.sampler import sample_antipodal_grasps
from graspaug.planning.settings import CEMSettings, SamplerSettings
from graspaug.render.crops import crops_from_depth_image
from graspaug.render.settings import CropGeometry, Intrinsics

#: A test of image grasps: grasps → (N,) bool, True for a grasp to keep.
Accept = Callable[[ImageGrasps], np.ndarray]

#: Ranked grasps, best first: the grasps, their qualities (n,) (NaN without a network) and the grasps scored in all.
Ranked = tuple[ImageGrasps, np.ndarray, int]


class GraspPolicy(Protocol):
    """What plans grasps on a depth image."""

    def plan_ranked(
        self, depth: np.ndarray, rng: np.random.Generator, top: int = 1, accept: Accept | None = None
    ) -> Ranked | None:
        """Up to ``top`` grasps on ``depth`` (H, W) m, best first, or None when there is none."""
        ...


class CrossEntropyGraspPolicy:
    """Plans grasps on depth images with a trained GQ-CNN (CPU, one thread is enough)."""

    def __init__(
        self,
        net: GQCNN | GQCNNEnsemble,
        intrinsics: Intrinsics,
        sampler: SamplerSettings = SamplerSettings(),
        cem: CEMSettings = CEMSettings(),
        geometry: CropGeometry = CropGeometry(),
    ) -> None:
        self.net, self.intrinsics, self.geometry = net.eval(), intrinsics, geometry
        self.sampler, self.cem = sampler, cem

    def quality(self, depth: np.ndarray, grasps: ImageGrasps) -> np.ndarray:
        """GQ-CNN success probability (N,) of each grasp in ``depth`` (H, W) m."""
        if len(grasps) == 0:
            return np.zeros(0, dtype=np.float32)
        crops = crops_from_depth_image(depth, grasps.centers, grasps.angles, self.geometry)
        with torch.inference_mode():
            q = self.net.success_probability(
                torch.from_numpy(crops).unsqueeze(1), torch.from_numpy(grasps.depths.astype(np.float32))
            )
        return q.numpy()

    def _valid(self, depth: np.ndarray, grasps: ImageGrasps) -> np.ndarray:
        b = self.sampler.min_dist_from_boundary
        h, w = depth.shape
        u, v = grasps.centers[:, 0], grasps.centers[:, 1]
        max_px = self.sampler.max_width * self.intrinsics.fx / np.maximum(grasps.depths, 1e-3)
        return (u >= b) & (u < w - b) & (v >= b) & (v < h - b) & (grasps.widths < max_px) & (grasps.depths > 0)

    def plan_ranked(
        self, depth: np.ndarray, rng: np.random.Generator, top: int = 1, accept: Accept | None = None
    ) -> Ranked | None:
        """The ``top`` best distinct grasps of the last cross-entropy iteration, best first, their
        qualities and the number of grasps scored in all; None when the image has no antipodal
        pair at all. With ``accept`` (grasps → (N,) bool) the ranking holds only accepted grasps
        of the last iteration and of the seeds (None when none is accepted). Near-duplicates of a
        better grasp are dropped (:func:`~graspaug.planning.grasps.distinct_grasps`), so fewer
        than ``top`` may come back; the best grasp is the same for every ``top``."""
        grasps = sample_antipodal_grasps(depth, self.intrinsics, self.sampler, self.cem.num_seed_samples, rng)
        if len(grasps) == 0:
            return None
        q = self.quality(depth, grasps)
        seeds, seed_q = grasps, q
        scored = len(grasps)
        for _ in range(self.cem.num_iters):
            n_elite = max(1, int(math.ceil(self.cem.elite_fraction * len(grasps))))
            if n_elite < 2:  # a mixture needs two grasps to fit: keep those scored so far
                break
            elite = grasps.take(np.argsort(-q, kind="stable")[:n_elite])
            components = max(
                1, min(self.cem.gmm_components, int(math.ceil(self.cem.gmm_component_fraction * n_elite)), n_elite)
            )
            gmm = GaussianMixture(
                n_components=components,
                covariance_type="full",
                reg_covar=1e-3,
                random_state=int(rng.integers(2**31 - 1)),
            ).fit(grasp_features(elite))
            features, _ = gmm.sample(self.cem.num_gmm_samples)
            sampled = grasps_from_features(features)
            sampled = sampled.take(self._valid(depth, sampled))
            if len(sampled) == 0:
                break
            grasps, q = sampled, self.quality(depth, sampled)
            scored += len(sampled)
        if accept is not None:
            grasps = ImageGrasps(
                *(
                    np.concatenate([getattr(grasps, k), getattr(seeds, k)])
                    for k in ("centers", "angles", "depths", "widths")
                )
            )
            q = np.concatenate([q, seed_q])
            keep = np.flatnonzero(accept(grasps))
            if len(keep) == 0:
                return None
            grasps, q = grasps.take(keep), q[keep]
        order = np.argsort(-q, kind="stable")  # the first is np.argmax(q)
        order = order[distinct_grasps(grasps.take(order), top)]  # near-duplicates dropped; the first kept
        return grasps.take(order), q[order], scored


class RandomAntipodalPolicy:
    """The reference without a network: antipodal seed grasps of the image, drawn at random
    (quality NaN)."""

    def __init__(self, intrinsics: Intrinsics, sampler: SamplerSettings = SamplerSettings()) -> None:
        self.intrinsics, self.sampler = intrinsics, sampler

    def plan_ranked(
        self, depth: np.ndarray, rng: np.random.Generator, top: int = 1, accept: Accept | None = None
    ) -> Ranked | None:
        """Up to ``top`` distinct antipodal seed grasps drawn at random (quality NaN), or None: the
        first ``top`` that are no near-duplicate of an earlier one
        (:func:`~graspaug.planning.grasps.distinct_grasps`) among up to 20 × ``top`` seeds (among
        the accepted ones with ``accept``). With ``top=1`` and no ``accept`` one seed is drawn."""
        count = top if accept is None and top == 1 else 20 * top
        grasps = sample_antipodal_grasps(depth, self.intrinsics, self.sampler, count, rng)
        if accept is not None and len(grasps):
            grasps = grasps.take(np.flatnonzero(accept(grasps)))
        grasps = grasps.take(distinct_grasps(grasps, top))
        if len(grasps) == 0:
            return None
        return grasps, np.full(len(grasps), np.nan), len(grasps)
