"""The lifelong loop's figures: each arm's curve over rounds with its interval band."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pandas as pd


def curve_series(curve: pd.DataFrame, arms: Sequence[str], figure: str = "ap") -> tuple[list[int], dict, dict]:
    """(rounds, arm → ``figure`` per round, arm → (low, high) per round) of a curve (:func:`curve_rows` of every
    round). The test AP of every arm starts at round 0's ``none`` (the base set alone, which every arm starts
    from), the gain at 0."""
    curve = curve.astype({"mean": float, "draws_low": float, "draws_high": float})  # a missing end: NaN
    rounds = sorted(curve["round"].unique())
    curve = curve[curve.figure == figure]
    series, bands = {}, {}
    for arm in arms:
        rows = curve[curve.arm == arm].set_index("round")
        start = curve[curve.arm == ("none" if figure == "ap" else arm)].set_index("round").loc[0]
        pick = lambda col: [start[col]] + [rows[col].get(r, np.nan) for r in rounds[1:]]  # noqa: B023, E731
        series[arm], bands[arm] = pick("mean"), (pick("draws_low"), pick("draws_high"))
    return rounds, series, bands
