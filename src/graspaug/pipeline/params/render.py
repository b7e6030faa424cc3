"""The ``render`` section: Dex-Net 2.0 style depth crops of every grasp."""

from __future__ import annotations

from graspaug.render.settings import RenderSettings
from graspaug.settings import Field, settings


@settings
class RenderParams(RenderSettings):
    """Dex-Net 2.0 style depth crops of every grasp seen from above (the GQ-CNN's data)."""

    shard_rows: int = Field(20000, ge=1, description="Datapoints per .npy shard.")
    n_examples: int = Field(
        24, ge=2, description="Crops in the example picture (half positive, half negative when there are enough)."
    )
