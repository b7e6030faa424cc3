"""Pinhole depth cameras: intrinsics, poses, projection and Dex-Net's random viewpoints."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from graspaug.settings import Field, settings


@settings
class Intrinsics:
    """A pinhole camera's image size (pixels) and intrinsics (pixels).

    Defaults: the Primesense Carmine / RealSense D435 depth camera Dex-Net 2.0 used,
    640×480 with fx = fy = 525 px and the principal point at the image center.
    """

    width: int = Field(640, ge=1, description="Image width (px).")
    height: int = Field(480, ge=1, description="Image height (px).")
    fx: float = Field(525.0, gt=0, description="Focal length along u (px; Primesense/D435 at 640×480: ~525).")
    fy: float = Field(525.0, gt=0, description="Focal length along v (px).")
    cx: float = Field(319.5, description="Principal point u (px; the image center is (width - 1) / 2).")
    cy: float = Field(239.5, description="Principal point v (px; the image center is (height - 1) / 2).")

    def __post_init__(self) -> None:
        if self.width < 1 or self.height < 1 or self.fx <= 0 or self.fy <= 0:
            raise ValueError(f"intrinsics need a positive image size and focal lengths, got {self}")

    def project(self, points: np.ndarray) -> np.ndarray:
        """Pixel coordinates (N, 2) as (u, v) of camera-frame points (N, 3) in front of the camera."""
        points = np.asarray(points, dtype=float)
        z = points[:, 2]
        return np.stack([self.fx * points[:, 0] / z + self.cx, self.fy * points[:, 1] / z + self.cy], axis=1)

    def rays(self, u: np.ndarray, v: np.ndarray) -> np.ndarray:
        """Camera-frame ray directions (N, 3) through pixels (u, v), scaled to unit z: a point at
        depth d on the ray is ``d * rays``."""
        u = np.asarray(u, dtype=float).ravel()
        v = np.asarray(v, dtype=float).ravel()
        return np.stack([(u - self.cx) / self.fx, (v - self.cy) / self.fy, np.ones_like(u)], axis=1)


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


@settings
class ViewpointRanges:
    """Dex-Net 2.0's random camera placement around an object resting at the table origin.

    The camera looks at a point ``object_offset`` (m, uniform in x and y) away from the object,
    from ``distance`` (m) away, tilted ``tilt_deg`` from straight down toward a uniform azimuth,
    and rolled uniformly about its axis.
    """

    distance: tuple[float, float] = Field((0.65, 0.75), description="Range of the camera's distance to its target point on the table (m).")
    tilt_deg: tuple[float, float] = Field((0.1, 5.0), description="Range of the optical axis' angle from straight down (deg).")
    object_offset: float = Field(0.1, ge=0, description="The camera aims up to this far from the object in x and y (m), so objects sit off the image center.")

    def __post_init__(self) -> None:
        if not 0 < self.distance[0] <= self.distance[1]:
            raise ValueError(f"camera distance range must be positive and ordered, got {self.distance}")
        if not 0 <= self.tilt_deg[0] <= self.tilt_deg[1] < 90:
            raise ValueError(f"camera tilt range must lie in [0, 90) degrees and be ordered, got {self.tilt_deg}")
        if self.object_offset < 0:
            raise ValueError(f"object offset must be >= 0, got {self.object_offset}")


def sample_viewpoint(ranges: ViewpointRanges, rng: np.random.Generator) -> CameraPose:
    """One random camera pose for an object resting at the table origin."""
    distance = rng.uniform(*ranges.distance)
    tilt = np.radians(rng.uniform(*ranges.tilt_deg))
    azimuth, roll = rng.uniform(0.0, 2 * np.pi, size=2)
    target = np.array([*rng.uniform(-ranges.object_offset, ranges.object_offset, size=2), 0.0])
    eye = target + distance * np.array([np.sin(tilt) * np.cos(azimuth), np.sin(tilt) * np.sin(azimuth), np.cos(tilt)])
    return look_at(eye, target, roll)
