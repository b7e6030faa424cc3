"""Settings of the renderer: grasp crops and one shape's datapoints."""
from __future__ import annotations

from graspaug.render.camera import Intrinsics, ViewpointRanges
from graspaug.settings import Field, settings


@settings
class CropGeometry:
    """Crop size around the grasp and output size (pixels); the first must be a multiple of the second."""

    crop_size: int = Field(96, ge=1, description="Side of the grasp-centered crop in image pixels (Dex-Net: 96).")
    out_size: int = Field(32, ge=1, description="Side of the stored crop after block averaging (Dex-Net: 32); must divide crop_size.")

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
    a seeded random subset; 0: all), approached from above over ``approach_distance`` (m).
    """

    max_poses: int = Field(5, ge=1, description="Most probable stable resting poses rendered per shape.")
    min_pose_probability: float = Field(0.01, ge=0, le=1, description="Stable poses less likely than this are pruned (Dex-Net: 0.01).")
    images_per_pose: int = Field(1, ge=1, description="Random camera views per stable pose (Dex-Net 2.0: 5; each view holds every table-parallel grasp).")
    max_grasps_per_image: int = Field(0, ge=0, description="At most this many grasps per view, a seeded random subset (0: all).")
    axis_tolerance_deg: float = Field(5.0, ge=0, le=90, description="A grasp is rendered in a pose if its jaw axis is within this angle of parallel to the table (deg).")
    approach_distance: float = Field(0.1, ge=0, description="Length of the straight approach from above checked for gripper collisions (m).")
    viewpoints: ViewpointRanges = Field(default_factory=ViewpointRanges, description="Dex-Net 2.0's random camera placement.")
    intrinsics: Intrinsics = Field(default_factory=Intrinsics, description="The depth camera.")
    crop: CropGeometry = Field(default_factory=CropGeometry, description="Grasp crop and stored image sizes.")
