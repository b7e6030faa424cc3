"""The critic study in words: each contrast as a line of text."""

from __future__ import annotations


def contrast_text(contrast: dict[str, dict], keys: list[str]) -> list[str | None]:
    """Per α key, one contrast (α key → :func:`~graspaug.experiments.stats.paired_contrast` dict) as
    ``"+1.23 [+0.45, +2.01]"`` (percentage points), or None where it has no mean."""
    return [
        None if d["mean"] is None else f"{d['mean']:+.2f} [{d['ci_low']:+.2f}, {d['ci_high']:+.2f}]"
        for d in (contrast[k] for k in keys)
    ]
