"""The ``ae`` section: the AutoEncoder-Critic network and its two training phases."""

from __future__ import annotations

from graspaug.nets.settings import AEConfig
from graspaug.settings import Field, settings
from graspaug.training.settings import AETrainConfig


@settings
class AEParams:
    """AutoEncoder-Critic network and its two training phases (paper Section III)."""

    net: AEConfig = Field(default_factory=AEConfig, description="Layer sizes.")
    train: AETrainConfig = Field(default_factory=AETrainConfig, description="The two training phases.")
