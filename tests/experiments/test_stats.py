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
    plain = weighted_average_precision(labels, scores, np.ones(len(objects)))
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


def test_the_verdict_interval_adds_the_seeds_t_and_the_objects_normal_half_widths_on_hand_made_tables():
    from graspaug.experiments.stats import nested_t_interval

    flat = nested_t_interval(np.full((3, 4), 0.02), np.full((3, 4, 500), 0.02))
    assert (flat["mean"], flat["low"], flat["high"]) == pytest.approx((0.02, 0.02, 0.02))
    assert (flat["n_draws"], flat["n_seeds"]) == (3, 4)
    # one draw, seeds alone vary: the t-interval over the seeds, exactly
    seeds = np.array([[0.0297, 0.0161, 0.0509, -0.0073]])  # issue #67's real gains per seed
    out = nested_t_interval(seeds, np.repeat(seeds[:, :, None], 200, axis=2))
    t = t_interval(seeds[0])
    assert (out["low"], out["high"]) == pytest.approx((t["low"], t["high"]))
    assert out["low"] == pytest.approx(-0.0165, abs=1e-4) and out["high"] == pytest.approx(0.0612, abs=1e-4)
    assert draw_verdict(out["low"], out["high"]) == "no effect we can claim in this draw of the data"
    # several draws: the draws' means over seeds are the replicates, on D − 1 degrees of freedom
    draws = np.array([[0.01, 0.03, 0.02, 0.02], [0.04, 0.04, 0.05, 0.03], [0.0, 0.01, -0.01, 0.0]])
    over = nested_t_interval(draws, np.repeat(draws[:, :, None], 200, axis=2))
    means = t_interval(draws.mean(axis=1))
    assert (over["low"], over["high"]) == pytest.approx((means["low"], means["high"]))
    # test objects alone vary (the same object resample in every cell): the normal interval of their resamples
    objects = np.random.default_rng(2).normal(0.0, 0.01, size=3000)
    alone = nested_t_interval(np.zeros((3, 4)), np.broadcast_to(objects, (3, 4, 3000)))
    assert alone["high"] == pytest.approx(1.959964 * objects.std(ddof=1)) and alone["low"] == -alone["high"]
    # both: the two half-widths in quadrature
    both = nested_t_interval(seeds, seeds[:, :, None] + objects)
    half = np.hypot(t["high"] - t["mean"], alone["high"])
    assert (both["low"], both["high"]) == pytest.approx((seeds.mean() - half, seeds.mean() + half))


def test_one_seed_of_one_draw_has_no_interval_and_no_verdict():
    from graspaug.experiments.stats import nested_contrast, nested_t_interval, verdict

    one = nested_t_interval(np.array([[0.02]]), np.random.default_rng(0).normal(0.02, 0.01, (1, 1, 300)))
    assert one["mean"] == pytest.approx(0.02) and one["low"] is None and one["high"] is None
    assert verdict(nested_contrast(one)) == "no interval (one seed, or a missing value): no verdict"
    missing = nested_t_interval(np.array([[0.02, np.nan]]), np.zeros((1, 2, 10)))
    assert missing["mean"] is None and missing["low"] is None


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
    assert draw_verdict(None, None) == "no interval (one seed, or a missing value): no verdict"
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


def test_a_share_of_a_real_gain_whose_interval_holds_zero_is_unbounded():
    """Issue #67: real gains per seed [+0.0297, +0.0161, +0.0509, −0.0073] gave, by the percentile bootstrap, the
    verdict "a gain" and a bounded share [−59%, +687%]; their t-interval holds zero, and so the share is unbounded."""
    from graspaug.experiments.stats import nested_t_interval, ratio_interval, share_text

    real = np.array([[0.0297, 0.0161, 0.0509, -0.0073]])
    pool = np.array([[0.02, 0.01, 0.015, 0.005]])
    flat = lambda a: np.repeat(a[..., None], 300, axis=2)  # noqa: E731
    out = ratio_interval(pool, flat(pool), real, flat(real))
    assert out["share"] == pytest.approx(pool.mean() / real.mean())
    assert not out["bounded"] and out["low"] is None and out["high"] is None
    den = nested_t_interval(real, flat(real))
    assert (out["denominator_low"], out["denominator_high"]) == (den["low"], den["high"])
    assert out["denominator_low"] < 0 < out["denominator_high"]
    assert share_text(out).endswith("[unbounded]")


def test_a_share_of_a_clearly_positive_gain_is_fiellers_on_the_seeds_and_wider_with_object_noise():
    from graspaug.experiments.stats import fieller_interval, ratio_interval

    rng = np.random.default_rng(5)
    real = rng.normal(0.05, 0.01, (1, 5))
    pool = 0.6 * real + rng.normal(0.0, 0.005, (1, 5))
    flat = lambda a: np.repeat(a[..., None], 300, axis=2)  # noqa: E731
    out, closed = ratio_interval(pool, flat(pool), real, flat(real)), fieller_interval(pool[0], real[0])
    assert out["bounded"] and out["low"] < out["share"] < out["high"]
    assert (out["share"], out["low"], out["high"]) == pytest.approx((closed["ratio"], closed["low"], closed["high"]))
    objects = rng.normal(0.0, 0.004, (300,))  # the same object resample moves both gains
    noisy = ratio_interval(pool, pool[..., None] + 0.5 * objects, real, real[..., None] + objects)
    assert noisy["share"] == out["share"] and noisy["high"] - noisy["low"] > out["high"] - out["low"]
    # the set holds exactly the θ whose difference's own interval holds zero: at either end, zero is on its edge
    from graspaug.experiments.stats import nested_t_interval

    for theta in (noisy["low"], noisy["high"]):
        edge = nested_t_interval(
            pool - theta * real, (pool[..., None] + 0.5 * objects) - theta * (real[..., None] + objects)
        )
        assert min(abs(edge["low"]), abs(edge["high"])) == pytest.approx(0.0, abs=1e-12)


def test_a_share_keeps_nothing_larger_than_its_resamples():
    """Issue #67: the old test inversion kept an R × R array (1.6 GB at 10,000 resamples); 200,000 would be 320 GB."""
    from graspaug.experiments.stats import ratio_interval

    rng = np.random.default_rng(0)
    real, pool = rng.normal(0.05, 0.01, (1, 4)), rng.normal(0.03, 0.01, (1, 4))
    objects = rng.normal(0.0, 0.003, 200_000)
    out = ratio_interval(pool, pool[..., None] + objects, real, real[..., None] + objects)
    assert out["bounded"] and out["low"] < out["share"] < out["high"]


def test_fieller_on_a_nan_input_is_not_bounded():
    from graspaug.experiments.stats import fieller_interval

    out = fieller_interval(np.array([0.01, np.nan, 0.02]), np.array([0.04, 0.05, 0.045]))
    assert not out["bounded"] and out["low"] is None and out["high"] is None


def test_average_precision_groups_tied_scores_as_sklearn_does():
    """Issue #67: tied scores are one threshold, so AP does not depend on the order of the datapoints."""
    labels = np.array([0, 1, 0, 1, 0, 0, 1, 0])
    scores = np.array([0.9, 0.9, 0.9, 0.9, 0.2, 0.2, 0.2, 0.2])
    assert average_precision_score(labels, scores) == pytest.approx(0.458333, abs=1e-6)
    ap = weighted_average_precision(labels, scores, np.ones(8))
    assert ap == pytest.approx(average_precision_score(labels, scores))
    for order in (np.argsort(-labels, kind="stable"), np.random.default_rng(1).permutation(8)):  # positives first
        assert weighted_average_precision(labels[order], scores[order], np.ones(8)) == pytest.approx(ap)
    rng = np.random.default_rng(3)
    y = rng.integers(0, 2, 400)
    s = np.round(rng.random(400) + 0.3 * y, 1).astype(np.float32)  # few distinct scores, as bfloat16 outputs give
    w = rng.integers(0, 4, (6, 400)).astype(np.float32)
    want = [average_precision_score(y, s, sample_weight=x) for x in w]
    assert weighted_average_precision(y, s, w) == pytest.approx(want, rel=1e-5)
    boot = ObjectBootstrap(np.arange(400) // 8, 20, 0)  # the bootstrap's AP is the same function
    counts = boot.object_counts[:, boot.object_index]
    want = [average_precision_score(y, s, sample_weight=x) for x in counts]
    assert boot.average_precision(y, s) == pytest.approx(want, rel=1e-5)


def test_a_t_interval_that_leaves_the_quantitys_range_is_no_interval():
    """Issue #62 item 8: two seeds of a success-rate difference gave ±3.177; too few seeds say so instead."""
    from graspaug.experiments.stats import DIFFERENCE_RANGE, t_interval

    two = t_interval([0.1, -0.15], bounds=DIFFERENCE_RANGE)
    assert two["mean"] == pytest.approx(-0.025) and two["low"] is None and not two["usable"]
    four = t_interval([0.02, 0.03, 0.025, 0.035], bounds=DIFFERENCE_RANGE)
    assert four["usable"] and -1 <= four["low"] < four["high"] <= 1


def test_the_object_bootstraps_ap_is_the_weighted_ap_of_its_object_counts():
    """ObjectBootstrap.average_precision works from the objects' counts at the thresholds that hold a positive (fast);
    it must give weighted_average_precision's figures, tied scores grouped, NaN where a resample has no positive."""
    from graspaug.experiments.stats import ObjectBootstrap, weighted_average_precision

    rng = np.random.default_rng(0)
    for trial in range(20):
        n, n_objects = int(rng.integers(5, 3000)), int(rng.integers(1, 40))
        objects = rng.integers(0, n_objects, n)
        labels = rng.random(n) < rng.choice([0.0, 0.02, 0.3])
        scores = np.round(rng.random(n), int(rng.integers(1, 4)))  # many ties
        boot = ObjectBootstrap(objects, 200, trial)
        slow = weighted_average_precision(labels, scores, boot.object_counts[:, boot.object_index])
        np.testing.assert_allclose(boot.average_precision(labels, scores), slow, rtol=1e-5)  # slow sums float32


def test_the_binned_bootstrap_ap_gives_the_object_loops_figures_to_1e_9():
    """The faster ObjectBootstrap.average_precision (datapoints binned by object and threshold, two products) against
    the object loop it replaced, on random data: continuous scores, heavy ties, a rare positive, objects of very
    different sizes, an object never drawn's worth of positives, and a resample without a positive (NaN in both)."""
    from graspaug.experiments.stats import ObjectBootstrap

    rng = np.random.default_rng(7)
    for trial in range(12):
        n_objects = int(rng.integers(2, 40))
        objects = rng.choice(n_objects, size=int(rng.integers(50, 3000)), p=rng.dirichlet(np.ones(n_objects) * 0.5))
        labels = rng.random(len(objects)) < [0.3, 0.02, 0.6][trial % 3]
        scores = labels + rng.normal(0, 1.0, len(objects))
        if trial % 2:
            scores = np.round(scores, 1)  # many tied scores
        boot = ObjectBootstrap(objects, 300, trial)
        old, new = boot.average_precision_by_objects(labels, scores), boot.average_precision(labels, scores)
        np.testing.assert_allclose(new, old, rtol=0, atol=1e-9)
        assert np.array_equal(np.isnan(new), np.isnan(old))
    one = ObjectBootstrap(np.r_[np.zeros(30), np.ones(30)], 200, 0)  # positives on one object only
    labels, scores = np.r_[np.zeros(30, bool), rng.random(30) < 0.5], rng.random(60)
    new, old = one.average_precision(labels, scores), one.average_precision_by_objects(labels, scores)
    assert np.isnan(new).any() and np.array_equal(np.isnan(new), np.isnan(old))
    np.testing.assert_allclose(new[~np.isnan(new)], old[~np.isnan(old)], rtol=0, atol=1e-9)
