"""The ``score`` section: rarity and graspness of every shape."""

from __future__ import annotations

from graspaug.settings import Field, settings


@settings
class ScoreParams:
    """Rarity (eq. 3-4 on AE-Critic latents) and graspness of every shape."""

    k: int = Field(20, ge=1, description="Neighbours in the rarity score, eq. (3)-(4) (scikit-learn LOF default: 20).")
    bins: int = Field(20, ge=2, description="Bins of the graspness and rarity histograms.")
