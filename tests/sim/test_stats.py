import numpy as np
import pytest

from graspaug.sim.stats import paired_test, wilson_interval


def test_wilson_interval_known_values():
    # 8 of 10: p = 0.8, z = 1.96 -> (0.490, 0.943) (Wilson 1927; e.g. Newcombe 1998 table I)
    low, high = wilson_interval(8, 10)
    assert low == pytest.approx(0.4902, abs=1e-4) and high == pytest.approx(0.9433, abs=1e-4)
    low, high = wilson_interval(10, 10)
    assert high == pytest.approx(1.0) and low == pytest.approx(0.7225, abs=1e-4)
    assert wilson_interval(0, 0) == (0.0, 1.0)


def test_paired_test_counts_discordant_attempts():
    before = np.array([1, 1, 1, 0, 0, 1, 1, 1], bool)
    after = np.array([1, 0, 0, 0, 1, 1, 0, 0], bool)
    result = paired_test(before, after)
    assert result["only_before"] == 4 and result["only_after"] == 1
    assert result["p_value"] == pytest.approx(0.375)  # two-sided binomial, 1 of 5 at 0.5
    assert paired_test(before, before)["p_value"] == 1.0
