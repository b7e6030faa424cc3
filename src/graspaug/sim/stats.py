"""Success rates with their uncertainty, and the paired comparison of two planners."""
from __future__ import annotations

import numpy as np
from scipy.stats import binomtest


def wilson_interval(successes: int, attempts: int, confidence: float = 0.95) -> tuple[float, float]:
    """Wilson score interval of a success rate (scipy); (0, 1) when there were no attempts."""
    if attempts == 0:
        return 0.0, 1.0
    ci = binomtest(int(successes), int(attempts)).proportion_ci(confidence_level=confidence, method="wilson")
    return float(ci.low), float(ci.high)


def paired_test(before: np.ndarray, after: np.ndarray) -> dict[str, float | int]:
    """Exact McNemar test of two planners on the same attempts: ``before``, ``after`` (N,) bool
    outcomes of the same drops. Counts the discordant attempts and gives the two-sided p-value
    of "neither planner wins the discordant attempts more often"."""
    before, after = np.asarray(before, dtype=bool), np.asarray(after, dtype=bool)
    only_before = int(np.sum(before & ~after))
    only_after = int(np.sum(after & ~before))
    n = only_before + only_after
    p = 1.0 if n == 0 else float(binomtest(only_after, n, 0.5).pvalue)
    return {"only_before": only_before, "only_after": only_after, "p_value": p}
