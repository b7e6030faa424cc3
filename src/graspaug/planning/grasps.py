"""Planar grasps in a depth image and Dex-Net's grasp feature vector.

An image grasp is a jaw center (u, v) in pixels, the jaw direction ``angle`` in the image
(radians, from the u axis toward v), the camera-frame depth ``depth`` (m) of the grasp center,
and the jaw opening ``width`` (px) between its two contact pixels. Jaw 1 sits at
center - half, jaw 2 at center + half, with half = 0.5 · width · (cos angle, sin angle).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class ImageGrasps:
    """N planar grasps in an image.

    Attributes
    ----------
    centers : (N, 2) float — jaw centers (u, v), px
    angles : (N,) float — jaw directions in (-π/2, π/2], rad (from the u axis toward v)
    depths : (N,) float — gripper depths (camera-frame z of the grasp centers), m
    widths : (N,) float — jaw openings between the contacts, px
    """

    centers: np.ndarray
    angles: np.ndarray
    depths: np.ndarray
    widths: np.ndarray

    def __len__(self) -> int:
        return len(self.angles)

    def take(self, index) -> ImageGrasps:
        return ImageGrasps(self.centers[index], self.angles[index], self.depths[index], self.widths[index])


def canonical_angles(angles: np.ndarray) -> np.ndarray:
    """Angles (N,) rad folded into (-π/2, π/2] (a parallel-jaw grasp is the same turned by π)."""
    folded = np.mod(angles + np.pi / 2, np.pi) - np.pi / 2
    return np.where(folded <= -np.pi / 2, folded + np.pi, folded)


def jaw_endpoints(centers: np.ndarray, angles: np.ndarray, widths: np.ndarray) -> np.ndarray:
    """The two jaw positions of each grasp.

    Parameters
    ----------
    centers : (n, 2) float — jaw centers (u, v), px
    angles : (n,) float — jaw directions, rad (from the u axis toward v)
    widths : (n,) float — jaw openings, px

    Returns
    -------
    (n, 2, 2) float — ``[:, 0]`` jaw 1 = center - half, ``[:, 1]`` jaw 2 = center + half, (u, v) px,
    with half = 0.5 · width · (cos angle, sin angle).
    """
    half = 0.5 * widths[:, None] * np.stack([np.cos(angles), np.sin(angles)], axis=1)
    return np.stack([centers - half, centers + half], axis=1)


def opening_widths(grasps: ImageGrasps, fx: float, fy: float) -> np.ndarray:
    """(N,) jaw openings (m) of image ``grasps`` seen by a camera of focal lengths ``fx``, ``fy`` (px): each
    opening ``widths`` (px) along its jaw direction, at its gripper depth ``depths`` (m)."""
    per_px = np.hypot(np.cos(grasps.angles) / fx, np.sin(grasps.angles) / fy)  # m per px per m of depth
    return per_px * grasps.widths * grasps.depths


def grasp_features(grasps: ImageGrasps) -> np.ndarray:
    """(N, 5) Dex-Net's grasp feature vector: jaw 1 (u, v) px, jaw 2 (u, v) px, the depth in cm."""
    jaws = jaw_endpoints(grasps.centers, grasps.angles, grasps.widths)
    return np.concatenate([jaws[:, 0], jaws[:, 1], 100.0 * grasps.depths[:, None]], axis=1)


def grasps_from_features(features: np.ndarray) -> ImageGrasps:
    """The grasps of Dex-Net feature vectors (N, 5) (inverse of :func:`grasp_features`)."""
    p1, p2 = features[:, 0:2], features[:, 2:4]
    axis = p2 - p1
    return ImageGrasps(
        centers=(p1 + p2) / 2,
        angles=canonical_angles(np.arctan2(axis[:, 1], axis[:, 0])),
        depths=features[:, 4] / 100.0,
        widths=np.linalg.norm(axis, axis=1),
    )


#: Near-duplicate rule of :func:`distinct_grasps`: centers closer than this share of the better grasp's opening ...
DUPLICATE_CENTER_FRACTION = 0.25
#: ... but never than this many pixels ...
DUPLICATE_MIN_CENTER_PX = 4.0
#: ... and jaw lines within this many degrees (mod 180°).
DUPLICATE_ANGLE_DEG = 15.0


def distinct_grasps(ranked: ImageGrasps, top: int) -> np.ndarray:
    """Non-maximum suppression in the image: indices (ascending, at most ``top``) of the grasps of
    ``ranked`` (best first) that are no near-duplicate of a better-ranked grasp kept before them.

    A grasp is a near-duplicate of a kept grasp when both hold: its center lies closer than
    ``max(DUPLICATE_CENTER_FRACTION × the kept grasp's opening, DUPLICATE_MIN_CENTER_PX)`` px
    (a quarter of the opening, at least 4 px) to the kept grasp's center, and its jaw line is
    within ``DUPLICATE_ANGLE_DEG`` (15°) of the kept grasp's (angles compared mod 180°: a
    parallel-jaw grasp turned by 180° is the same grasp). Depth is not compared: two such grasps
    look alike in the image. The first (best) grasp is always kept, so ``top=1`` gives ``[0]``;
    nothing random is involved. Fewer than ``top`` come back when fewer grasps are distinct.
    """
    if top < 1 or len(ranked) == 0:
        return np.zeros(0, dtype=int)
    kept = [0]
    radius = [max(DUPLICATE_CENTER_FRACTION * float(ranked.widths[0]), DUPLICATE_MIN_CENTER_PX)]
    max_angle = np.radians(DUPLICATE_ANGLE_DEG)
    for j in range(1, len(ranked)):
        if len(kept) >= top:
            break
        near = np.linalg.norm(ranked.centers[kept] - ranked.centers[j], axis=1) < np.asarray(radius)
        turn = np.abs(ranked.angles[kept] - ranked.angles[j]) % np.pi
        parallel = np.minimum(turn, np.pi - turn) < max_angle
        if not np.any(near & parallel):
            kept.append(j)
            radius.append(max(DUPLICATE_CENTER_FRACTION * float(ranked.widths[j]), DUPLICATE_MIN_CENTER_PX))
    return np.asarray(kept, dtype=int)
