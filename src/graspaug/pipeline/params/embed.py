"""The ``embed`` section: latents of every shape and their t-SNE map."""

from __future__ import annotations

from graspaug.settings import Field, settings


@settings
class EmbedParams:
    """Latents of every shape and their t-SNE map."""

    perplexity: float = Field(
        30.0, gt=0, description="t-SNE perplexity (lowered automatically below the number of shapes)."
    )
