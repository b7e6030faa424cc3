"""Grasp planning on a depth image: antipodal seeds on depth edges, GQ-CNN scores, and the
cross-entropy method (Dex-Net 2.0's ``CrossEntropyRobustGraspingPolicy``).

An image grasp is a jaw center (u, v) in pixels, the jaw direction ``angle`` in the image
(radians, from the u axis toward v), the camera-frame depth ``depth`` (m) of the grasp center,
and the jaw opening ``width_px`` between its two contact pixels. The crops the GQ-CNN scores are
the same 96 → 32 crops the training data has (:func:`graspaug.render.crops.crops_from_depth_image`).
"""
from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import torch
from sklearn.mixture import GaussianMixture

from graspaug.nets.gqcnn import GQCNN, GQCNNEnsemble
from graspaug.render.camera import CameraPose, Intrinsics
from graspaug.render.crops import CropGeometry, crops_from_depth_image
from graspaug.sim.settings import SamplerSettings
from graspaug.sim.settings import CEMSettings


@dataclass(frozen=True)
class ImageGrasps:
    """N planar grasps in an image: ``centers`` (N, 2) (u, v) px, ``angles`` (N,) rad in
    (-π/2, π/2], ``depths`` (N,) m (camera frame), ``widths`` (N,) px between the contacts."""

    centers: np.ndarray
    angles: np.ndarray
    depths: np.ndarray
    widths: np.ndarray

    def __len__(self) -> int:
        return len(self.angles)

    def take(self, index) -> ImageGrasps:
        return ImageGrasps(self.centers[index], self.angles[index], self.depths[index], self.widths[index])


@dataclass(frozen=True)
class PlannedGrasp:
    """The chosen grasp, its predicted success probability, and how long planning took (s)."""

    grasp: ImageGrasps  # one row
    quality: float
    planning_time: float
    candidates: int  # grasps scored in all


def _canonical(angles: np.ndarray) -> np.ndarray:
    """Angles folded into (-π/2, π/2] (a parallel-jaw grasp is the same turned by π)."""
    folded = np.mod(angles + np.pi / 2, np.pi) - np.pi / 2
    return np.where(folded <= -np.pi / 2, folded + np.pi, folded)


def surface_depth(depth: np.ndarray, p1: np.ndarray, p2: np.ndarray, samples: int = 12) -> np.ndarray:
    """Smallest depth (m) on the segments p1 → p2 (N, 2) (u, v) px: the top of what lies
    between the jaws."""
    t = np.linspace(0.0, 1.0, samples)
    points = p1[:, None, :] + (p2 - p1)[:, None, :] * t[None, :, None]
    u = np.clip(np.rint(points[..., 0]).astype(int), 0, depth.shape[1] - 1)
    v = np.clip(np.rint(points[..., 1]).astype(int), 0, depth.shape[0] - 1)
    return depth[v, u].min(axis=1)


def sample_antipodal_grasps(depth: np.ndarray, intrinsics: Intrinsics, settings: SamplerSettings, count: int,
                            rng: np.random.Generator) -> ImageGrasps:
    """Up to ``count`` antipodal grasps on the depth edges of ``depth`` (H, W) m.

    Edge pixels have |∇depth| above the threshold and lie at least ``min_dist_from_boundary``
    from the border; their outward normal is ∇depth / |∇depth| (toward the farther side). A pair
    (p1, p2) is antipodal when the jaw line p1 → p2 lies within the friction cone of both
    contacts and the pair fits the gripper at the depth of p1.
    """
    grad_v, grad_u = np.gradient(depth)
    magnitude = np.hypot(grad_u, grad_v)
    edges = magnitude > settings.depth_grad_thresh
    b, (h, w) = settings.min_dist_from_boundary, depth.shape
    edges[:b], edges[h - b:], edges[:, :b], edges[:, w - b:] = False, False, False, False
    v, u = np.nonzero(edges)
    empty = ImageGrasps(np.zeros((0, 2)), np.zeros(0), np.zeros(0), np.zeros(0))
    if len(u) < 2:
        return empty
    keep = rng.permutation(len(u))[: settings.max_edge_pixels]
    u, v = u[keep], v[keep]
    points = np.stack([u, v], axis=1).astype(float)
    normals = np.stack([grad_u[v, u], grad_v[v, u]], axis=1) / magnitude[v, u, None]
    first = rng.permutation(len(points))[: max(1, 4 * count // 10 + 200)]
    offsets = points[None, :, :] - points[first, None, :]  # (F, E, 2)
    distance = np.linalg.norm(offsets, axis=2)
    max_px = settings.max_width * intrinsics.fx / depth[v[first], u[first]]
    direction = offsets / np.maximum(distance, 1e-9)[..., None]
    cone = math.cos(math.atan(settings.friction_coef))
    ok = (distance > 2.0) & (distance < max_px[:, None])
    ok &= np.einsum("fek,fk->fe", direction, -normals[first]) >= cone
    ok &= np.einsum("fek,ek->fe", direction, normals) >= cone
    pairs_f, pairs_e = np.nonzero(ok)
    if len(pairs_f) == 0:
        return empty
    chosen = rng.choice(len(pairs_f), size=min(count, len(pairs_f)), replace=False)
    p1, p2 = points[first[pairs_f[chosen]]], points[pairs_e[chosen]]
    axis = p2 - p1
    surface = surface_depth(depth, p1, p2)
    depths = surface + rng.uniform(settings.min_depth_offset, settings.max_depth_offset, size=len(surface))
    return ImageGrasps(centers=(p1 + p2) / 2, angles=_canonical(np.arctan2(axis[:, 1], axis[:, 0])), depths=depths,
                       widths=np.linalg.norm(axis, axis=1))


def edge_normals(depth: np.ndarray, settings: SamplerSettings) -> tuple[np.ndarray, np.ndarray]:
    """Edge mask (H, W) of ``depth`` (m) and unit outward normals (H, W, 2) (u, v) there, as
    :func:`sample_antipodal_grasps` finds them (without the border margin)."""
    grad_v, grad_u = np.gradient(depth)
    magnitude = np.hypot(grad_u, grad_v)
    edges = magnitude > settings.depth_grad_thresh
    with np.errstate(divide="ignore", invalid="ignore"):
        normals = np.stack([grad_u, grad_v], axis=2) / magnitude[..., None]
    return edges, np.nan_to_num(normals)


def antipodal_in_image(depth: np.ndarray, grasps: ImageGrasps, settings: SamplerSettings, fingertip_offset: float = 0.0,
                       search_px: int = 2, clearance_px: tuple[int, int] = (2, 6)) -> np.ndarray:
    """(N,) bool: each grasp's jaws meet depth edges within ``search_px`` px whose outward
    normals hold the jaw line inside the friction cone (the sampler's test), and beyond each jaw,
    ``clearance_px`` px outward along the jaw axis (and 3 px to either side), the image is no
    nearer than the grasp depth plus ``fingertip_offset`` (m, how far the fingertips reach past
    the grasp center): the fingers can go down (not into the object's flanks or the table)."""
    h, w = depth.shape
    edges, normals = edge_normals(depth, settings)
    cone = math.cos(math.atan(settings.friction_coef))
    direction = np.stack([np.cos(grasps.angles), np.sin(grasps.angles)], axis=1)
    half = 0.5 * grasps.widths[:, None] * direction
    ok = np.ones(len(grasps), dtype=bool)
    offsets = np.arange(-search_px, search_px + 1)
    du, dv = (a.ravel() for a in np.meshgrid(offsets, offsets))
    across = np.stack([-direction[:, 1], direction[:, 0]], axis=1)
    steps = np.arange(clearance_px[0], clearance_px[1] + 1)
    for sign in (-1.0, 1.0):  # jaw 1 at center - half (outward: -direction), jaw 2 at center + half
        jaw = grasps.centers + sign * half
        u = np.clip(np.rint(jaw[:, 0, None]).astype(int) + du, 0, w - 1)
        v = np.clip(np.rint(jaw[:, 1, None]).astype(int) + dv, 0, h - 1)
        outward = sign * direction
        facing = np.einsum("nkc,nc->nk", normals[v, u], outward) >= cone
        ok &= np.any(edges[v, u] & facing, axis=1)
        points = (jaw[:, None, None, :] + outward[:, None, None, :] * steps[None, :, None, None]
                  + across[:, None, None, :] * np.array([-3.0, 0.0, 3.0])[None, None, :, None])
        pu = np.clip(np.rint(points[..., 0]).astype(int), 0, w - 1)
        pv = np.clip(np.rint(points[..., 1]).astype(int), 0, h - 1)
        ok &= depth[pv, pu].reshape(len(grasps), -1).min(axis=1) >= grasps.depths + fingertip_offset
    return ok


def grasp_features(grasps: ImageGrasps) -> np.ndarray:
    """(N, 5) Dex-Net's grasp feature vector: both jaw endpoints (u, v) px and the depth in cm."""
    half = 0.5 * grasps.widths[:, None] * np.stack([np.cos(grasps.angles), np.sin(grasps.angles)], axis=1)
    return np.concatenate([grasps.centers - half, grasps.centers + half, 100.0 * grasps.depths[:, None]], axis=1)


def grasps_from_features(features: np.ndarray) -> ImageGrasps:
    """Inverse of :func:`grasp_features`."""
    p1, p2 = features[:, 0:2], features[:, 2:4]
    axis = p2 - p1
    return ImageGrasps(centers=(p1 + p2) / 2, angles=_canonical(np.arctan2(axis[:, 1], axis[:, 0])),
                       depths=features[:, 4] / 100.0, widths=np.linalg.norm(axis, axis=1))


class CrossEntropyGraspPolicy:
    """Plans one grasp per depth image with a trained GQ-CNN (CPU, one thread is enough)."""

    def __init__(self, net: GQCNN | GQCNNEnsemble, intrinsics: Intrinsics, sampler: SamplerSettings = SamplerSettings(),
                 cem: CEMSettings = CEMSettings(), geometry: CropGeometry = CropGeometry()) -> None:
        self.net, self.intrinsics, self.sampler, self.cem, self.geometry = net.eval(), intrinsics, sampler, cem, geometry

    def quality(self, depth: np.ndarray, grasps: ImageGrasps) -> np.ndarray:
        """GQ-CNN success probability (N,) of each grasp in ``depth`` (H, W) m."""
        if len(grasps) == 0:
            return np.zeros(0, dtype=np.float32)
        crops = crops_from_depth_image(depth, grasps.centers, grasps.angles, self.geometry)
        with torch.inference_mode():
            q = self.net.success_probability(torch.from_numpy(crops).unsqueeze(1), torch.from_numpy(grasps.depths.astype(np.float32)))
        return q.numpy()

    def _valid(self, depth: np.ndarray, grasps: ImageGrasps) -> np.ndarray:
        b = self.sampler.min_dist_from_boundary
        h, w = depth.shape
        u, v = grasps.centers[:, 0], grasps.centers[:, 1]
        max_px = self.sampler.max_width * self.intrinsics.fx / np.maximum(grasps.depths, 1e-3)
        return (u >= b) & (u < w - b) & (v >= b) & (v < h - b) & (grasps.widths < max_px) & (grasps.depths > 0)

    def plan_ranked(self, depth: np.ndarray, rng: np.random.Generator, top: int = 1,
                    accept: Callable[[ImageGrasps], np.ndarray] | None = None) -> tuple[ImageGrasps, np.ndarray, int] | None:
        """The ``top`` best grasps of the last cross-entropy iteration, best first, their
        qualities and the number of grasps scored in all; None when the image has no antipodal
        pair at all. With ``accept`` (grasps → (N,) bool) the ranking holds only accepted grasps
        of the last iteration and of the seeds (None when none is accepted)."""
        grasps = sample_antipodal_grasps(depth, self.intrinsics, self.sampler, self.cem.num_seed_samples, rng)
        if len(grasps) == 0:
            return None
        q = self.quality(depth, grasps)
        seeds, seed_q = grasps, q
        scored = len(grasps)
        for _ in range(self.cem.num_iters):
            n_elite = max(1, int(math.ceil(self.cem.elite_fraction * len(grasps))))
            elite = grasps.take(np.argsort(-q, kind="stable")[:n_elite])
            components = max(1, min(self.cem.gmm_components, int(math.ceil(self.cem.gmm_component_fraction * n_elite)), n_elite))
            gmm = GaussianMixture(n_components=components, covariance_type="full", reg_covar=1e-3,
                                  random_state=int(rng.integers(2**31 - 1))).fit(grasp_features(elite))
            features, _ = gmm.sample(self.cem.num_gmm_samples)
            sampled = grasps_from_features(features)
            sampled = sampled.take(self._valid(depth, sampled))
            if len(sampled) == 0:
                break
            grasps, q = sampled, self.quality(depth, sampled)
            scored += len(sampled)
        if accept is not None:
            grasps = ImageGrasps(*(np.concatenate([getattr(grasps, k), getattr(seeds, k)]) for k in ("centers", "angles", "depths", "widths")))
            q = np.concatenate([q, seed_q])
            keep = np.flatnonzero(accept(grasps))
            if len(keep) == 0:
                return None
            grasps, q = grasps.take(keep), q[keep]
        order = np.argsort(-q, kind="stable")[:top]  # the first is np.argmax(q)
        return grasps.take(order), q[order], scored

    def plan(self, depth: np.ndarray, rng: np.random.Generator) -> PlannedGrasp | None:
        """The best grasp after the cross-entropy iterations, or None when the image has no
        antipodal pair at all."""
        start = time.perf_counter()
        ranked = self.plan_ranked(depth, rng)
        if ranked is None:
            return None
        grasps, q, scored = ranked
        return PlannedGrasp(grasp=grasps, quality=float(q[0]), planning_time=time.perf_counter() - start, candidates=scored)


class RandomAntipodalPolicy:
    """The reference without a network: one antipodal seed grasp of the image, drawn at random
    (quality NaN)."""

    def __init__(self, intrinsics: Intrinsics, sampler: SamplerSettings = SamplerSettings()) -> None:
        self.intrinsics, self.sampler = intrinsics, sampler

    def plan_ranked(self, depth: np.ndarray, rng: np.random.Generator, top: int = 1,
                    accept: Callable[[ImageGrasps], np.ndarray] | None = None) -> tuple[ImageGrasps, np.ndarray, int] | None:
        """``top`` antipodal seed grasps drawn at random (quality NaN), or None; with ``accept``,
        ``top`` of the accepted ones among up to 20 × ``top`` seeds."""
        grasps = sample_antipodal_grasps(depth, self.intrinsics, self.sampler, top if accept is None else 20 * top, rng)
        if accept is not None and len(grasps):
            grasps = grasps.take(np.flatnonzero(accept(grasps))[:top])
        if len(grasps) == 0:
            return None
        return grasps, np.full(len(grasps), np.nan), len(grasps)

    def plan(self, depth: np.ndarray, rng: np.random.Generator) -> PlannedGrasp | None:
        start = time.perf_counter()
        ranked = self.plan_ranked(depth, rng)
        if ranked is None:
            return None
        return PlannedGrasp(grasp=ranked[0], quality=float("nan"), planning_time=time.perf_counter() - start, candidates=1)


def grasp_in_table_frame(grasps: ImageGrasps, camera: CameraPose, intrinsics: Intrinsics) -> tuple[np.ndarray, np.ndarray]:
    """Grasp centers (N, 3) m and jaw angles (N,) rad (in the table plane, from the table's x
    axis) of image grasps seen by ``camera``: the center pixel deprojected at the grasp depth,
    the image jaw direction carried to the table and flattened onto it."""
    rays = intrinsics.rays(grasps.centers[:, 0], grasps.centers[:, 1])
    centers = camera.to_table(rays * grasps.depths[:, None])
    direction_cam = np.stack([np.cos(grasps.angles), np.sin(grasps.angles), np.zeros(len(grasps))], axis=1)
    direction = direction_cam @ camera.rotation.T
    return centers, np.arctan2(direction[:, 1], direction[:, 0])
