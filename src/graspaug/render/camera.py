"""Pinhole depth cameras: poses, look-at placement and Dex-Net's random viewpoints.

The camera settings (:class:`Intrinsics`, :class:`ViewpointRanges`) live in :mod:`graspaug.render.settings`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from graspaug.render.settings import ViewpointRanges


@dataclass(frozen=True)
class CameraPose:
    """Where a camera is: ``rotation`` (3, 3) has the camera's x, y, z axes as columns, in the
    table frame; ``position`` (3,) is its optical center in the table frame (m)."""

    rotation: np.ndarray
    position: np.ndarray

    def to_camera(self, points: np.ndarray) -> np.ndarray:
        """Table-frame points (N, 3) → camera frame."""
        return (np.asarray(points, dtype=float) - self.position) @ self.rotation

    def to_table(self, points: np.ndarray) -> np.ndarray:
        """Camera-frame points (N, 3) → table frame."""
        return np.asarray(points, dtype=float) @ self.rotation.T + self.position

    def in_frame(self, pose: np.ndarray) -> CameraPose:
        """This camera expressed in the frame that ``pose`` (4, 4) places in the table frame
        (e.g. an object's own frame, for an object resting in that pose)."""
        rotation, translation = pose[:3, :3], pose[:3, 3]
        return CameraPose(rotation=rotation.T @ self.rotation, position=rotation.T @ (self.position - translation))

    @property
    def height(self) -> float:
        """Height of the optical center above the table (m)."""
        return float(self.position[2])

    @property
    def tilt(self) -> float:
        """Angle between the optical axis and straight down (radians)."""
        return float(np.arccos(np.clip(-self.rotation[2, 2], -1.0, 1.0)))


def look_at(eye: np.ndarray, target: np.ndarray, roll: float = 0.0) -> CameraPose:
    """The camera at ``eye`` looking at ``target`` (table frame, m), turned by ``roll`` (radians)
    about its optical axis. With roll 0 the image's x axis is the table's x axis as seen from above
    (for a camera straight above the target)."""
    eye = np.asarray(eye, dtype=float)
    z = np.asarray(target, dtype=float) - eye
    z /= np.linalg.norm(z)
    reference = np.array([1.0, 0.0, 0.0]) if abs(z[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    x = reference - z * (reference @ z)
    x /= np.linalg.norm(x)
    y = np.cross(z, x)
    x, y = np.cos(roll) * x + np.sin(roll) * y, -np.sin(roll) * x + np.cos(roll) * y
    return CameraPose(rotation=np.stack([x, y, z], axis=1), position=eye)


def sample_viewpoint(ranges: ViewpointRanges, rng: np.random.Generator) -> CameraPose:
    """One random camera pose for an object resting at the table origin."""
    distance = rng.uniform(*ranges.distance)
    tilt = np.radians(rng.uniform(*ranges.tilt_deg))
    azimuth, roll = rng.uniform(0.0, 2 * np.pi, size=2)
    target = np.array([*rng.uniform(-ranges.object_offset, ranges.object_offset, size=2), 0.0])
    eye = target + distance * np.array([np.sin(tilt) * np.cos(azimuth), np.sin(tilt) * np.sin(azimuth), np.cos(tilt)])
    return look_at(eye, target, roll)
