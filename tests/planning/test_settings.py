"""The planner's settings check their own invariants."""

from __future__ import annotations

import pytest

from graspaug.planning.settings import CEMSettings, SamplerSettings


def test_depth_offsets_must_be_ordered():
    assert SamplerSettings(min_depth_offset=0.01, max_depth_offset=0.01).max_depth_offset == 0.01
    with pytest.raises(ValueError, match=r"max_depth_offset: must be >= min_depth_offset \(0.05\); got 0.04"):
        SamplerSettings(min_depth_offset=0.05)


def test_ranges_are_checked_by_field():
    with pytest.raises(ValueError, match="friction_coef"):
        SamplerSettings(friction_coef=0.0)
    with pytest.raises(ValueError, match="elite_fraction"):
        CEMSettings(elite_fraction=1.5)
