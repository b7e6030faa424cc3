import numpy as np
import pytest

from graspaug.experiments.critic import interpolate, outlier_contrast, outlier_table, random_pairs, summarize
from graspaug.experiments.stats import PairBootstrap


def test_random_pairs_are_distinct_shapes():
    pairs = random_pairs(50, 20, 8, np.random.default_rng(0))
    assert pairs.shape == (8, 2)
    assert len(np.unique(pairs)) == 16 and np.all(pairs[:, 0] != pairs[:, 1])


def test_interpolate_hits_both_ends():
    z = np.arange(6, dtype=np.float32).reshape(3, 2)
    mixed = interpolate(z, np.array([[0, 2]]), np.array([0.0, 0.5, 1.0], dtype=np.float32))
    assert np.allclose(mixed[0], [z[0], (z[0] + z[2]) / 2, z[2]])


def test_outlier_table_counts_voxels_outside_the_largest_piece():
    grid = np.zeros((8, 8, 8), bool)
    grid[1:4, 1:4, 1:4] = True  # 27 voxels
    grid[6, 6, 6] = True  # 1 stray voxel
    table = outlier_table(np.stack([grid, np.zeros_like(grid)])[None])
    assert table.shape == (1, 2)
    assert table[0, 0] == pytest.approx(100 / 28) and np.isnan(table[0, 1])


def test_intervals_bracket_the_mean_and_shrink_with_more_pairs():
    rng = np.random.default_rng(0)
    few, many = rng.exponential(2.0, (20, 1)), rng.exponential(2.0, (400, 1))
    narrow = summarize(many, PairBootstrap(400, 2000, rng))[0]
    wide = summarize(few, PairBootstrap(20, 2000, rng))[0]
    for s in (narrow, wide):
        assert s["ci_low"] < s["mean"] < s["ci_high"]
    assert narrow["ci_high"] - narrow["ci_low"] < wide["ci_high"] - wide["ci_low"]
    assert abs(narrow["mean"] - 2.0) < 0.3


def test_paired_contrast_is_exact_for_a_constant_shift_and_skips_empty_pairs():
    """Model A has 1 point more than B on every pair: the paired difference is 1 with a zero-width
    interval, however much the pairs vary between themselves; a pair empty under A is left out."""
    rng = np.random.default_rng(1)
    b = rng.exponential(3.0, (30, 2))
    a = b + 1.0
    a[0, 1] = np.nan
    diff = outlier_contrast(a, b, PairBootstrap(30, 500, rng))
    for d in diff:
        assert (
            d["mean"] == pytest.approx(1.0) and d["ci_low"] == pytest.approx(1.0) and d["ci_high"] == pytest.approx(1.0)
        )
    unpaired = summarize(a, PairBootstrap(30, 500, rng))[0]
    assert unpaired["ci_high"] - unpaired["ci_low"] > 0.5  # the per-model interval carries the pair-to-pair spread


def test_all_empty_column_gives_nulls():
    assert summarize(np.full((5, 1), np.nan), PairBootstrap(5, 100, np.random.default_rng(0)))[0] == {
        "mean": None,
        "ci_low": None,
        "ci_high": None,
    }
