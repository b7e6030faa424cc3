"""Settings of the renderer: the depth camera, its random viewpoints, grasp crops and one shape's datapoints."""

from __future__ import annotations

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


@settings
class ViewpointRanges:
    """Dex-Net 2.0's random camera placement around an object resting at the table origin.

    The camera looks at a point ``object_offset`` (m, uniform in x and y) away from the object,
    from ``distance`` (m) away, tilted ``tilt_deg`` from straight down toward a uniform azimuth,
    and rolled uniformly about its axis.
    """

    distance: tuple[float, float] = Field(
        (0.65, 0.75), description="Range of the camera's distance to its target point on the table (m)."
    )
    tilt_deg: tuple[float, float] = Field(
        (0.1, 5.0), description="Range of the optical axis' angle from straight down (deg)."
    )
    object_offset: float = Field(
        0.1,
        ge=0,
        description=(
            "The camera aims up to this far from the object in x and y (m), so objects sit off the image center."
        ),
    )

    def __post_init__(self) -> None:
        if not 0 < self.distance[0] <= self.distance[1]:
            raise ValueError(f"camera distance range must be positive and ordered, got {self.distance}")
        if not 0 <= self.tilt_deg[0] <= self.tilt_deg[1] < 90:
            raise ValueError(f"camera tilt range must lie in [0, 90) degrees and be ordered, got {self.tilt_deg}")
        if self.object_offset < 0:
            raise ValueError(f"object offset must be >= 0, got {self.object_offset}")


@settings
class CropGeometry:
    """Crop size around the grasp and output size (pixels); the first must be a multiple of the second."""

    crop_size: int = Field(96, ge=1, description="Side of the grasp-centered crop in image pixels (Dex-Net: 96).")
    out_size: int = Field(
        32, ge=1, description="Side of the stored crop after block averaging (Dex-Net: 32); must divide crop_size."
    )

    def __post_init__(self) -> None:
        if self.out_size < 1 or self.crop_size < self.out_size or self.crop_size % self.out_size:
            raise ValueError(f"crop_size ({self.crop_size}) must be a positive multiple of out_size ({self.out_size})")

    @property
    def factor(self) -> int:
        return self.crop_size // self.out_size


@settings
class RenderSettings:
    """How one shape's datapoints are made (Dex-Net 2.0's recipe by default).

    ``max_poses`` most probable stable poses with probability >= ``min_pose_probability``;
    ``images_per_pose`` random camera views of each; in each view every grasp whose jaw axis is
    within ``axis_tolerance_deg`` of parallel to the table (at most ``max_grasps_per_image``,
    a seeded random subset; 0: all), approached from above over ``approach_distance`` (m), the
    palm keeping ``palm_clearance`` (m) above the object.
    """

    max_poses: int = Field(5, ge=1, description="Most probable stable resting poses rendered per shape.")
    min_pose_probability: float = Field(
        0.01, ge=0, le=1, description="Stable poses less likely than this are pruned (Dex-Net: 0.01)."
    )
    images_per_pose: int = Field(
        1,
        ge=1,
        description="Random camera views per stable pose (Dex-Net 2.0: 5; each view holds every table-parallel grasp).",
    )
    max_grasps_per_image: int = Field(
        0, ge=0, description="At most this many grasps per view, a seeded random subset (0: all)."
    )
    axis_tolerance_deg: float = Field(
        5.0,
        ge=0,
        le=90,
        description=(
            "A grasp is rendered in a pose if its jaw axis is within this angle of parallel to the table (deg)."
        ),
    )
    approach_distance: float = Field(
        0.1, ge=0, description="Length of the straight approach from above checked for gripper collisions (m)."
    )
    palm_clearance: float = Field(
        0.002,
        ge=0,
        description="Gap the palm must keep from the object at the grasp for the approach to count as collision "
        "free (m; 0: the palm may end touching the object's top).",
    )
    viewpoints: ViewpointRanges = Field(
        default_factory=ViewpointRanges, description="Dex-Net 2.0's random camera placement."
    )
    intrinsics: Intrinsics = Field(default_factory=Intrinsics, description="The depth camera.")
    crop: CropGeometry = Field(default_factory=CropGeometry, description="Grasp crop and stored image sizes.")
