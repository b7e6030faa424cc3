"""Antipodal grasps on the depth edges of an image (Dex-Net 2.0's depth-image sampler), and the
image test that a grasp's jaws meet such edges and can go down beside the object."""

from __future__ import annotations

import math

import numpy as np

from graspaug.planning.grasps import ImageGrasps, canonical_angles, jaw_endpoints
from graspaug.planning.settings import SamplerSettings
from graspaug.render.settings import Intrinsics


def depth_edges(depth: np.ndarray, threshold: float) -> tuple[np.ndarray, np.ndarray]:
    """The depth edges of an image and their outward normals.

    Parameters
    ----------
    depth : (H, W) float — depth image, m
    threshold : float — depth gradient above which a pixel is an edge pixel, m per px

    Returns
    -------
    edges : (H, W) bool — |∇depth| > ``threshold`` (a new array the caller may change)
    normals : (H, W, 2) float — at edge pixels ∇depth / |∇depth| as (u, v), the unit normal
        toward the farther side; 0 elsewhere
    """
    grad_v, grad_u = np.gradient(depth)
    magnitude = np.hypot(grad_u, grad_v)
    edges = magnitude > threshold
    normals = np.zeros(depth.shape + (2,))
    v, u = np.nonzero(edges)
    normals[v, u] = np.stack([grad_u[v, u], grad_v[v, u]], axis=1) / magnitude[v, u, None]
    return edges, normals


def surface_depth(depth: np.ndarray, p1: np.ndarray, p2: np.ndarray, samples: int = 12) -> np.ndarray:
    """(N,) smallest depth (m) of ``depth`` (H, W) m on the segments p1 → p2 (N, 2) (u, v) px:
    the top of what lies between the jaws."""
    t = np.linspace(0.0, 1.0, samples)
    points = p1[:, None, :] + (p2 - p1)[:, None, :] * t[None, :, None]
    u = np.clip(np.rint(points[..., 0]).astype(int), 0, depth.shape[1] - 1)
    v = np.clip(np.rint(points[..., 1]).astype(int), 0, depth.shape[0] - 1)
    return depth[v, u].min(axis=1)


def sample_antipodal_grasps(
    depth: np.ndarray, intrinsics: Intrinsics, settings: SamplerSettings, count: int, rng: np.random.Generator
) -> ImageGrasps:
    """Up to ``count`` antipodal grasps on the depth edges of ``depth`` (H, W) m.

    Edge pixels (:func:`depth_edges`) lie at least ``min_dist_from_boundary`` px from the
    border. A pair (p1, p2) is antipodal when the jaw line p1 → p2 lies within the friction cone
    of both contacts and the pair fits the gripper at the depth of p1.
    """
    edges, normal_image = depth_edges(depth, settings.depth_grad_thresh)
    b, (h, w) = settings.min_dist_from_boundary, depth.shape
    edges[:b], edges[h - b :], edges[:, :b], edges[:, w - b :] = False, False, False, False
    v, u = np.nonzero(edges)
    empty = ImageGrasps(np.zeros((0, 2)), np.zeros(0), np.zeros(0), np.zeros(0))
    if len(u) < 2:
        return empty
    keep = rng.permutation(len(u))[: settings.max_edge_pixels]
    u, v = u[keep], v[keep]
    points = np.stack([u, v], axis=1).astype(float)
    normals = normal_image[v, u]
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
    angles = canonical_angles(np.arctan2(axis[:, 1], axis[:, 0]))
    return ImageGrasps(centers=(p1 + p2) / 2, angles=angles, depths=depths, widths=np.linalg.norm(axis, axis=1))


def antipodal_in_image(
    depth: np.ndarray,
    grasps: ImageGrasps,
    settings: SamplerSettings,
    fingertip_offset: float = 0.0,
    search_px: int = 2,
    clearance_px: tuple[int, int] = (2, 6),
) -> np.ndarray:
    """(N,) bool: whether the image shows each grasp antipodal and reachable.

    Each jaw must meet a depth edge (:func:`depth_edges`, no border margin) within ``search_px``
    px whose outward normal holds the jaw line inside the friction cone (the sampler's test), and
    beyond each jaw, ``clearance_px`` px outward along the jaw axis (and 3 px to either side), the
    image ``depth`` (H, W) m must be no nearer than the grasp depth plus ``fingertip_offset`` (m,
    how far the fingertips reach past the grasp center): the fingers can go down (not into the
    object's flanks or the table).
    """
    h, w = depth.shape
    edges, normals = depth_edges(depth, settings.depth_grad_thresh)
    cone = math.cos(math.atan(settings.friction_coef))
    direction = np.stack([np.cos(grasps.angles), np.sin(grasps.angles)], axis=1)
    jaws = jaw_endpoints(grasps.centers, grasps.angles, grasps.widths)
    ok = np.ones(len(grasps), dtype=bool)
    offsets = np.arange(-search_px, search_px + 1)
    du, dv = (a.ravel() for a in np.meshgrid(offsets, offsets))
    across = np.stack([-direction[:, 1], direction[:, 0]], axis=1)
    steps = np.arange(clearance_px[0], clearance_px[1] + 1)
    for side, sign in ((0, -1.0), (1, 1.0)):  # jaw 1 (outward: -direction), jaw 2 (outward: +direction)
        jaw = jaws[:, side]
        u = np.clip(np.rint(jaw[:, 0, None]).astype(int) + du, 0, w - 1)
        v = np.clip(np.rint(jaw[:, 1, None]).astype(int) + dv, 0, h - 1)
        outward = sign * direction
        facing = np.einsum("nkc,nc->nk", normals[v, u], outward) >= cone
        ok &= np.any(edges[v, u] & facing, axis=1)
        points = (
            jaw[:, None, None, :]
            + outward[:, None, None, :] * steps[None, :, None, None]
            + across[:, None, None, :] * np.array([-3.0, 0.0, 3.0])[None, None, :, None]
        )
        pu = np.clip(np.rint(points[..., 0]).astype(int), 0, w - 1)
        pv = np.clip(np.rint(points[..., 1]).astype(int), 0, h - 1)
        ok &= depth[pv, pu].reshape(len(grasps), -1).min(axis=1) >= grasps.depths + fingertip_offset
    return ok
