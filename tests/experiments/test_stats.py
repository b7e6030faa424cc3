"""The experiments' statistics: t-intervals over seeds, the object bootstrap (test objects,
trial objects), weighted AP, Wilson intervals and McNemar's test."""

import numpy as np
import pytest
from scipy import stats as scipy_stats
from sklearn.metrics import average_precision_score

from graspaug.experiments.stats import (
    ObjectBootstrap,
    draw_scope,
    draw_verdict,
    percentile_interval,
    t_interval,
    weighted_average_precision,
    wilson_interval,
)


def test_t_interval_on_a_hand_made_table():
    result = t_interval([0.01, 0.03, 0.02])  # mean 0.02, SD 0.01, t(0.975, 2) = 4.3027
    assert result["mean"] == pytest.approx(0.02) and result["n_seeds"] == 3
    half = 4.302653 * 0.01 / np.sqrt(3)
    assert (result["low"], result["high"]) == pytest.approx((0.02 - half, 0.02 + half), abs=1e-6)
    five = t_interval([0.1, 0.2, 0.3, 0.4, 0.5])
    assert five["high"] - five["mean"] == pytest.approx(
        scipy_stats.t.ppf(0.975, 4) * np.std([0.1, 0.2, 0.3, 0.4, 0.5], ddof=1) / np.sqrt(5)
    )
    assert t_interval([0.05])["low"] is None and t_interval([None, 0.05, float("nan")])["n_seeds"] == 1


def test_the_bootstrap_resamples_objects_not_datapoints():
    rng = np.random.default_rng(0)
    objects = np.repeat([f"obj{i}" for i in range(12)], rng.integers(5, 40, 12))  # uneven datapoints per object
    boot = ObjectBootstrap(objects, n_resamples=200, seed=1)
    weights = boot.object_counts[:, boot.object_index]
    for name in np.unique(objects):  # every datapoint of an object is drawn together, as often as its object
        rows = weights[:, objects == name]
        assert (rows == rows[:, :1]).all()
    assert (boot.object_counts.sum(axis=1) == 12).all()  # 12 objects drawn per resample, not len(objects) datapoints
    assert not np.allclose(weights.sum(axis=1), len(objects))  # so the datapoint count varies
    labels = rng.integers(0, 2, len(objects))
    scores = rng.random(len(objects)) + 0.3 * labels
    order = np.argsort(-scores)
    plain = weighted_average_precision(labels[order].astype(float), np.ones(len(objects)))
    assert plain == pytest.approx(average_precision_score(labels, scores))  # unweighted, it is sklearn's AP
    resampled = boot.average_precision(labels, scores)
    assert resampled.shape == (200,) and resampled.std() > 0
    keep = boot.object_counts[0, boot.object_index]  # one resample's AP is the AP of its objects, repeated
    repeated = np.repeat(np.arange(len(objects)), keep.astype(int))
    assert resampled[0] == pytest.approx(average_precision_score(labels[repeated], scores[repeated]))


def test_bootstrap_over_objects_covers_the_mean_and_sees_object_spread():
    objects = np.repeat(np.arange(30), 6)
    same = np.tile([1.0, 0.0, 0.0, 0.0, 0.0, 0.0], 30)  # every object +1/6
    low, high = percentile_interval(ObjectBootstrap(objects, 1000, 0).means(same))
    assert low == pytest.approx(1 / 6) and high == pytest.approx(1 / 6)  # no spread between objects: no width
    mixed = np.where(objects % 2 == 0, 1.0, -0.5)  # half the objects gain, half lose
    low, high = percentile_interval(ObjectBootstrap(objects, 2000, 1).means(mixed))
    assert low < 0.25 < high and 0.35 < high - low < 0.7  # 2 × 1.96 × 0.75 / √30 = 0.54


def test_wilson_interval_known_values():
    # 8 of 10: p = 0.8, z = 1.96 -> (0.490, 0.943) (Wilson 1927; e.g. Newcombe 1998 table I)
    low, high = wilson_interval(8, 10)
    assert low == pytest.approx(0.4902, abs=1e-4) and high == pytest.approx(0.9433, abs=1e-4)
    low, high = wilson_interval(10, 10)
    assert high == pytest.approx(1.0) and low == pytest.approx(0.7225, abs=1e-4)
    assert wilson_interval(0, 0) == (0.0, 1.0)


def test_a_contrasts_headline_is_its_mean_and_interval_ends_rounded():
    from graspaug.experiments.stats import contrast, headline

    c = contrast(0.0123456, "seeds", 4, seeds=(-0.001, None), objects=(0.5, 0.6), per_seed=[0.1, 0.2])
    assert headline(c) == {"mean": 0.01235, "lo": -0.001, "hi": None}  # its `over` interval, not the other
    assert headline({**c, "over": "objects"}) == {"mean": 0.01235, "lo": 0.5, "hi": 0.6}


def test_the_nested_interval_covers_each_source_of_variance_on_hand_made_tables():
    from graspaug.experiments.stats import nested_interval, percentile_interval

    rng = np.random.default_rng(0)
    flat = nested_interval(np.full((3, 4), 0.02), np.full((3, 4, 500), 0.02), rng)
    assert flat == pytest.approx({"mean": 0.02, "low": 0.02, "high": 0.02, "n_draws": 3, "n_seeds": 4})
    # draws alone vary: the bootstrap of the mean of 60 draw effects, SE = SD / sqrt(60)
    effects = rng.normal(0.1, 0.05, size=60)
    full = np.repeat(effects[:, None], 4, axis=1)
    out = nested_interval(full, np.repeat(full[:, :, None], 4000, axis=2), np.random.default_rng(1))
    se = effects.std() / np.sqrt(60)
    assert out["mean"] == pytest.approx(effects.mean())
    assert out["low"] == pytest.approx(effects.mean() - 1.96 * se, abs=0.25 * se)
    assert out["high"] == pytest.approx(effects.mean() + 1.96 * se, abs=0.25 * se)
    # test objects alone vary (the same object resample in every cell): the object bootstrap's interval
    objects = rng.normal(0.0, 0.01, size=3000)
    alone = nested_interval(np.zeros((3, 4)), np.broadcast_to(objects, (3, 4, 3000)), np.random.default_rng(2))
    assert (alone["low"], alone["high"]) == pytest.approx(percentile_interval(objects))
    # seeds on top of objects: wider than objects alone
    seeds = rng.normal(0.0, 0.02, size=(3, 4))
    both = nested_interval(seeds, seeds[:, :, None] + objects, np.random.default_rng(3))
    assert both["high"] - both["low"] > alone["high"] - alone["low"]


def test_the_fieller_interval_inverts_the_t_test_of_the_paired_difference():
    from scipy import stats

    from graspaug.experiments.stats import fieller_interval

    gain, real_gain = np.array([0.010, 0.020, 0.015, 0.012]), np.array([0.040, 0.035, 0.045, 0.041])
    out = fieller_interval(gain, real_gain)
    assert out["bounded"] and out["low"] < out["ratio"] < out["high"]
    assert out["ratio"] == pytest.approx(gain.mean() / real_gain.mean())
    critical = stats.t.ppf(0.975, 3)
    for theta in (out["low"], out["high"]):  # at either end x - θ y is exactly on the edge of significance
        d = gain - theta * real_gain
        assert abs(d.mean() / (d.std(ddof=1) / 2)) == pytest.approx(critical)
    noisy = fieller_interval(gain, np.array([0.03, -0.02, 0.01, -0.015]))  # the real gain is not clearly nonzero
    assert not noisy["bounded"] and noisy["low"] is None and noisy["high"] is None


def test_weighted_roc_auc_is_sklearns_with_ties_and_weights():
    from sklearn.metrics import roc_auc_score

    from graspaug.experiments.stats import weighted_roc_auc

    rng = np.random.default_rng(3)
    labels = rng.integers(0, 2, 300).astype(bool)
    scores = np.round(rng.random(300) + 0.4 * labels, 1)  # rounded: many ties
    weights = rng.integers(0, 4, (5, 300)).astype(float)
    got = weighted_roc_auc(labels, scores, weights)
    want = [roc_auc_score(labels, scores, sample_weight=w) for w in weights]
    assert got == pytest.approx(want)
    assert weighted_roc_auc(labels, scores, np.ones(300)) == pytest.approx(roc_auc_score(labels, scores))
    assert np.isnan(weighted_roc_auc(labels, scores, labels.astype(float)))  # no negative left: undefined
    boot = ObjectBootstrap(np.arange(300) // 10, 50, 0)
    assert boot.roc_auc(labels, scores).shape == (50,)


def test_a_one_draw_interval_is_a_gain_or_loss_in_this_draw_only_and_says_where_the_draws_are_combined():
    assert draw_verdict(-0.055, -0.014) == "a loss in this draw of the data"  # not "a real loss"
    assert draw_verdict(0.01, 0.03) == "a gain in this draw of the data"
    assert draw_verdict(-0.03, 0.02) == "no effect we can claim in this draw of the data"
    assert draw_verdict(None, None) == "no effect we can claim in this draw of the data"
    assert draw_verdict(-0.05, -0.01, n_draws=3) == "a loss over 3 draws of the data"
    scope = draw_scope(2, [0, 1, 2, 3], "ap")
    assert "`data_seed` = 2" in scope and "training seeds [0, 1, 2, 3] (`gqcnn.seeds`)" in scope
    assert "does not cover other draws" in scope
    assert "`graspaug study attribution --draws 0 1 2`" in scope and '"Over three draws of the data"' in scope
    assert "graspaug study lifelong --draws 0 1 2" in draw_scope(0, [0], "lifelong")


def test_one_contrast_type_names_each_interval_by_what_it_covers():
    """Every experiment's contrast has the same keys; its verdict, text and metrics read the interval it names."""
    from graspaug.experiments.stats import contrast, interval_text, verdict

    c = contrast(0.02, "objects", 4, objects=(0.01, 0.03), seeds=(-0.01, 0.05), n_trials=8)
    assert list(c)[:10] == [
        "mean", "seeds_low", "seeds_high", "objects_low", "objects_high", "draws_low", "draws_high", "over", "n_seeds",
        "n_draws",
    ]  # fmt: skip
    assert c["draws_low"] is None and c["n_trials"] == 8
    assert verdict(c) == "a gain in this draw of the data"
    assert verdict({**c, "over": "seeds"}) == "no effect we can claim in this draw of the data"
    assert interval_text(c, "+.2f") == "+0.02 [+0.01, +0.03]"
    assert interval_text(c, "+.2f", over="draws") == "+0.02 [n/a, n/a]" and interval_text(None) == "n/a"
    over_draws = contrast(-0.02, "draws", 4, 3, draws=(-0.03, -0.01))
    assert verdict(over_draws) == "a loss over 3 draws of the data"
    with pytest.raises(ValueError, match="over must be one of"):
        contrast(0.0, "t")


def _nested_gain(mean: float, low: float, high: float, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """A gain's (draws, seeds) values and (draws, seeds, resamples) object resamples whose nested bootstrap
    (:func:`nested_means` over one set of indices) has the given 2.5% and 97.5% percentiles: returned as the
    (R,) nested means, shifted and scaled onto ``low``, ``high``, with the mean of all cells ``mean``."""
    from graspaug.experiments.stats import nested_indices, nested_means

    cells = rng.normal(0.0, 1.0, size=(3, 4, 4000))
    nested = nested_means(cells, nested_indices(3, 4, 4000, np.random.default_rng(7)))
    q_low, q_high = np.quantile(nested, [0.025, 0.975])
    return low + (nested - q_low) * (high - low) / (q_high - q_low), mean


def test_a_share_of_a_real_gain_whose_interval_holds_zero_is_unbounded():
    """Issue #58: a real-pool gain of +0.0001 [-0.0059, +0.0068] gave a share of +1321% with the "bounded"
    percentile interval of the resampled ratios, [-677%, +848%], which excludes its own value."""
    from graspaug.experiments.stats import percentile_interval, ratio_interval, share_text

    rng = np.random.default_rng(58)
    real, real_mean = _nested_gain(0.0001, -0.0059, 0.0068, rng)
    pool = 0.001321 + 0.5 * (real - real_mean) + rng.normal(0.0, 0.002, size=real.shape)
    assert percentile_interval(real) == pytest.approx((-0.0059, 0.0068))
    out = ratio_interval(0.001321, real_mean, pool, real)
    assert out["share"] == pytest.approx(13.21)
    assert not out["bounded"] and out["low"] is None and out["high"] is None
    assert (out["denominator_low"], out["denominator_high"]) == pytest.approx((-0.0059, 0.0068))
    assert share_text(out) == "+1321% [unbounded]"
    old_low, old_high = percentile_interval(pool / real)  # the old method: bounded, and its value outside it
    assert not old_low <= out["share"] <= old_high


def test_a_share_of_a_clearly_positive_gain_matches_fiellers_closed_form_on_paired_data():
    from graspaug.experiments.stats import ObjectBootstrap, fieller_interval, ratio_interval

    rng = np.random.default_rng(5)
    real = rng.normal(0.05, 0.05, size=400)  # paired: one (pool gain, real gain) per object
    pool = 0.6 * real + rng.normal(0.0, 0.03, size=400)
    boot = ObjectBootstrap(np.arange(400), 4000, 1)
    out = ratio_interval(pool.mean(), real.mean(), boot.means(pool), boot.means(real))
    closed = fieller_interval(pool, real)
    assert out["bounded"] and out["low"] < out["share"] < out["high"]
    assert out["share"] == pytest.approx(closed["ratio"])
    width = closed["high"] - closed["low"]
    assert out["low"] == pytest.approx(closed["low"], abs=0.05 * width)  # within bootstrap error
    assert out["high"] == pytest.approx(closed["high"], abs=0.05 * width)
    assert out["denominator_low"] > 0


def test_a_t_interval_that_leaves_the_quantitys_range_is_no_interval():
    """Issue #62 item 8: two seeds of a success-rate difference gave ±3.177; too few seeds say so instead."""
    from graspaug.experiments.stats import DIFFERENCE_RANGE, t_interval

    two = t_interval([0.1, -0.15], bounds=DIFFERENCE_RANGE)
    assert two["mean"] == pytest.approx(-0.025) and two["low"] is None and not two["usable"]
    four = t_interval([0.02, 0.03, 0.025, 0.035], bounds=DIFFERENCE_RANGE)
    assert four["usable"] and -1 <= four["low"] < four["high"] <= 1
