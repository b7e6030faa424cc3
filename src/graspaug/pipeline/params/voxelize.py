"""The ``voxelize`` section: solid occupancy grids for the AutoEncoder."""

from __future__ import annotations

from typing import Literal

from graspaug.settings import Field, settings


@settings
class VoxelizeParams:
    """Solid occupancy grids for the AutoEncoder."""

    resolution: Literal[16, 32, 64, 128] = Field(32, description="Voxels per side R (32 on CPU, 64 in the paper).")
    margin: int = Field(1, ge=0, le=4, description="Empty voxels kept around the shape's largest extent.")
