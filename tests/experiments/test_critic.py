import numpy as np
import pandas as pd
import pytest

from graspaug.experiments.critic.figures import EXAMPLE_ALPHAS, example_rows, outlier_columns, outlier_lines
from graspaug.experiments.critic.numbers import (
    MODEL_LABELS,
    finite_or_none,
    interpolant_contrast,
    interpolate,
    outlier_contrast,
    outlier_table,
    random_pairs,
    study_headline,
    study_metrics,
    summarize,
)
from graspaug.experiments.critic.words import contrast_text
from graspaug.experiments.stats import PairBootstrap, contrast


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
        assert s["objects_low"] < s["mean"] < s["objects_high"]
    assert narrow["objects_high"] - narrow["objects_low"] < wide["objects_high"] - wide["objects_low"]
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
            d["mean"] == pytest.approx(1.0)
            and d["objects_low"] == pytest.approx(1.0)
            and d["objects_high"] == pytest.approx(1.0)
        )
    unpaired = summarize(a, PairBootstrap(30, 500, rng))[0]
    assert (
        unpaired["objects_high"] - unpaired["objects_low"] > 0.5
    )  # the per-model interval carries the pair-to-pair spread


def test_all_empty_column_gives_nulls():
    assert summarize(np.full((5, 1), np.nan), PairBootstrap(5, 100, np.random.default_rng(0)))[0] == contrast(
        None, "objects"
    )


def test_study_metrics_tables_every_model_and_contrast():
    """A constant 2-point gap between the AE-Critic and the control shows as an exact contrast; empty grids are
    counted; the wide table and its picture data carry the same means."""
    rng = np.random.default_rng(2)
    keys = ["0.00", "0.50"]
    base = rng.exponential(3.0, (6, 2))
    pct = {"ae": base + 1.0, "ae_extra": base.copy(), "ae_critic": base + 2.0}
    pct["ae"][0, 0] = np.nan
    critic = finite_or_none({"auc": 0.75, "real_mean": float("nan")})
    assert critic == {"auc": 0.75, "real_mean": None}
    metrics = study_metrics(pct, PairBootstrap(6, 200, rng), keys, critic, 200)
    assert metrics["n_pairs"] == 6 and metrics["n_decoded_per_model"] == 12 and metrics["critic_auc"] == 0.75
    assert metrics["empty_grids"] == {"ae": 1, "ae_extra": 0, "ae_critic": 0}
    assert list(metrics["outlier_pct"]) == list(MODEL_LABELS)
    gap = metrics["contrast"]["critic_vs_control"]
    assert all(gap[k]["mean"] == pytest.approx(2.0) == gap[k]["objects_low"] for k in keys)
    assert contrast_text(gap, keys) == ["+2.00 [+2.00, +2.00]"] * 2
    assert contrast_text({"0.00": {"mean": None}}, ["0.00"]) == [None]

    wide = pd.DataFrame(outlier_columns(metrics["outlier_pct_ci"], [0.0, 0.5], keys))
    series, intervals = outlier_lines(wide)
    assert list(series) == list(intervals) == list(MODEL_LABELS.values())
    assert series["AE-Critic"][1] == pytest.approx(metrics["outlier_pct"]["ae_critic"]["0.50"])
    low, high = intervals["AE"]
    assert np.all(low <= series["AE"]) and np.all(series["AE"] <= high)


def test_example_rows_one_row_per_pair_and_model():
    grids = np.zeros((2, len(EXAMPLE_ALPHAS), 4, 4, 4), bool)
    grids[..., 1:3, 1:3, 1:3] = True
    rows, row_labels, col_labels = example_rows({m: grids for m in MODEL_LABELS})
    assert len(rows) == 6 and len(rows[0]) == len(col_labels) == 7
    assert row_labels[:3] == ["pair 1 AE", "pair 1 AE + extra epochs", "pair 1 AE-Critic"]
    assert col_labels[0] == "α=0.00" and col_labels[-1] == "α=1.00"


def test_the_headline_averages_the_interpolants_per_pair_and_leaves_reconstructions_out():
    """α = 0 (a reconstruction) differs by 5 points, the interpolants by 1 and 3: the headline is 2, exactly;
    an empty grid drops that α of its pair only."""
    rng = np.random.default_rng(3)
    keys = ["0.00", "0.25", "0.50"]
    control = rng.exponential(3.0, (8, 3))
    critic = control + np.array([5.0, 1.0, 3.0])
    boot = PairBootstrap(8, 200, rng)
    c = interpolant_contrast(critic, control, keys, boot)
    assert (
        c["mean"] == pytest.approx(2.0)
        and c["objects_low"] == pytest.approx(2.0)
        and c["objects_high"] == pytest.approx(2.0)
    )
    critic[0, 2] = np.nan  # pair 0 keeps α = 0.25 alone: 1.0
    assert interpolant_contrast(critic, control, keys, boot)["mean"] == pytest.approx((7 * 2.0 + 1.0) / 8)
    pct = {"ae": control, "ae_extra": control, "ae_critic": control + np.array([5.0, 1.0, 3.0])}
    study = study_metrics(pct, boot, keys, {"auc": 0.6}, 200)
    assert study_headline(study) == {"mean": 2.0, "lo": 2.0, "hi": 2.0, "auc": 0.6}
