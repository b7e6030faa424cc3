"""The critic study in words: each contrast as a line of text."""

from __future__ import annotations

from graspaug.experiments.stats import interval_text


def contrast_text(contrast: dict[str, dict], keys: list[str]) -> list[str | None]:
    """Per α key, one contrast (α key → :func:`~graspaug.experiments.stats.paired_contrast` dict) as
    ``"+1.23 [+0.45, +2.01]"`` (percentage points), or None where it has no mean."""
    return [None if contrast[k]["mean"] is None else interval_text(contrast[k], "+.2f") for k in keys]
