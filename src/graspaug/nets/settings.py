"""Layer sizes of the two networks (the nets themselves: ``ae_critic.py``, ``gqcnn.py``)."""

from __future__ import annotations

import math
from typing import Literal

from graspaug.settings import Field, settings


@settings
class AEConfig:
    """Layer sizes (params section ``ae.net``)."""

    resolution: int = Field(32, description="R: voxels per side, a power of two >= 8; must equal voxelize.resolution.")
    z_dim: int = Field(128, ge=2, description="Latent size (paper: 128).")
    base_width: int = Field(
        16,
        ge=1,
        description=(
            "Channels of the first conv layer; doubles per down-sampling layer up to top_width (paper profile: 64)."
        ),
    )
    top_width: int = Field(128, ge=1, description="Channels of the 4×4×4 map before the FC layer (paper: 512).")
    output: Literal["occupancy", "sdf"] = Field(
        "sdf",
        description=(
            "What a grid holds, in and out: `sdf` (the truncated signed distance / truncation, in [-1, 1], negative "
            "inside; tanh out, an L1 loss weighted near the surface; meshed by marching cubes at 0 with sub-voxel "
            "faces and no opening or smoothing) or `occupancy` (0/1 in, a logit out; a decode is meshed by threshold, "
            "opening, marching cubes at 0.5 and smoothing: the paper's, which the `paper` profile keeps)."
        ),
    )
    truncation: float = Field(
        3.0, gt=0, description="With output `sdf`: the distance (voxels) beyond which a signed distance is clamped."
    )

    @property
    def n_down(self) -> int:
        """Stride-2 layers from R³ to 4³."""
        return int(round(math.log2(self.resolution // 4)))

    @property
    def widths(self) -> list[int]:
        """Channels after each down-sampling conv, then after the stride-1 conv."""
        down = [min(self.base_width * 2**i, self.top_width) for i in range(self.n_down)]
        return down + [self.top_width]

    def __post_init__(self):
        r = self.resolution
        if r < 8 or r & (r - 1):
            raise ValueError(f"resolution must be a power of two >= 8, got {r}")


@settings
class GQCNNConfig:
    """Layer sizes (params section ``gqcnn.net``)."""

    image_size: int = Field(32, ge=4, description="Crop side the network takes (px); must equal render.crop.out_size.")
    filters: int = Field(
        8, ge=1, description="Channels of each conv layer (Dex-Net 2.0 / paper profile: 64; 8 fits the CPU budget)."
    )
    fc: int = Field(64, ge=1, description="Width of fc3 and fc4 (Dex-Net: 1024).")
    pose_fc: int = Field(16, ge=1, description="Width of the gripper-depth layer pc1 (Dex-Net: 16).")
    pool_after_conv2: bool = Field(True, description="Max pool after conv2_2 (Dex-Net's 2018 config; 2017: none).")
    image_input: Literal["depth", "depth_minus_gripper"] = Field(
        "depth_minus_gripper",
        description=(
            "What the conv layers see: the crop minus the gripper depth (gqcnn's `im_depth_sub`: each pixel's height "
            "relative to the fingertips; the default), or the depth crop itself (Dex-Net 2.0)."
        ),
    )

    def __post_init__(self) -> None:
        if self.image_size % (4 if self.pool_after_conv2 else 2):
            raise ValueError(f"image_size {self.image_size} must be divisible by the pooling")
        if min(self.filters, self.fc, self.pose_fc) < 1:
            raise ValueError(f"layer widths must be >= 1, got {self}")
