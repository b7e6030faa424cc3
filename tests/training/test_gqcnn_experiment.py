"""The GQ-CNN experiment's design and statistics: object-wise validation, paired seeds,
t-intervals over seeds, a bootstrap over test objects."""
import numpy as np
import pytest
import torch
from scipy import stats as scipy_stats
from sklearn.metrics import average_precision_score

from graspaug.experiments.ap import declared_contrasts
from graspaug.experiments.networks import initial_weights, seed_members, seed_variants, stream_seeds, weights_digest
from graspaug.experiments.stats import ObjectBootstrap, t_interval, weighted_average_precision
from graspaug.nets.settings import GQCNNConfig
from graspaug.training.gqcnn_data import experiment_split, training_shapes

TRAIN = [f"rnd_{i:03d}" for i in range(60)]
BASE = {10: TRAIN[:10], 20: TRAIN[:20]}  # nested, as generate draws them


def test_validation_is_disjoint_from_every_training_set_and_the_same_for_every_variant():
    split = experiment_split(TRAIN, BASE, n_validation=8, seed=3)
    assert split == experiment_split(TRAIN, BASE, n_validation=8, seed=3)  # no training seed, variant or pool enters
    assert len(split.validation) == 8 and not set(split.validation) & set(BASE[20])
    assert set(split.real_pool) == set(TRAIN) - set(BASE[20]) - set(split.validation)
    assert set(split.ceiling) == set(TRAIN) - set(split.validation)
    for variant in seed_variants([10, 20], [0.0, 0.5, 1.0], [10, 20], ceiling=True):
        shapes, generated = training_shapes(variant, split)
        assert not set(shapes) & set(split.validation), variant
        assert set(BASE[variant.base_size]) <= set(shapes) if variant.pool != "ceiling" else len(shapes) == 52
        if variant.pool == "real":
            assert len(shapes) == variant.base_size + round(variant.ratio * variant.base_size) and generated == 0
        elif variant.pool in ("targeted", "random"):
            assert generated == round(variant.ratio * variant.base_size)
    assert experiment_split(TRAIN, BASE, 8, seed=4).validation != split.validation  # the global seed draws it


def test_a_real_pool_too_small_names_the_keys_to_change():
    split = experiment_split(TRAIN, BASE, n_validation=30, seed=0)  # 10 shapes left for the real pool
    variant = next(v for v in seed_variants([20], [1.0], [20], False) if v.pool == "real")
    with pytest.raises(ValueError, match="needs 20 more train shapes; 10 lie outside.*gqcnn.val_shapes"):
        training_shapes(variant, split)
    with pytest.raises(ValueError, match="gqcnn.val_shapes = 41, but only 40"):
        experiment_split(TRAIN, BASE, n_validation=41, seed=0)


def test_the_networks_of_a_seed_share_initial_weights_and_seeds_differ():
    config = GQCNNConfig(filters=4, fc=8, pose_fc=4)
    first = initial_weights(config, stream_seeds(0, 1)[0])
    torch.manual_seed(123)  # whatever ran before does not matter
    again = initial_weights(config, stream_seeds(0, 1)[0])
    other = initial_weights(config, stream_seeds(0, 2)[0])
    assert weights_digest(first) == weights_digest(again) != weights_digest(other)
    assert all(torch.equal(first[k], again[k]) for k in first)
    assert len({*stream_seeds(0, 1), *stream_seeds(0, 2), *stream_seeds(1, 1)}) == 6  # init and noise streams never collide


def test_members_of_a_seed_start_apart_and_member_zero_is_the_seeds_own_network():
    config = GQCNNConfig(filters=4, fc=8, pose_fc=4)
    inits, noise_seeds = seed_members(config, 0, 1, 3)
    assert weights_digest(inits[0]) == weights_digest(initial_weights(config, stream_seeds(0, 1)[0])) and noise_seeds[0] == stream_seeds(0, 1)[1]
    assert len({weights_digest(w) for w in inits}) == 3 and seed_members(config, 0, 1, 3)[1] == noise_seeds  # distinct, reproducible
    streams = {s for seed in range(4) for m in range(8) for s in stream_seeds(0, seed, m)}
    assert len(streams) == 4 * 8 * 2  # no member's stream is another seed's or member's


def test_t_interval_on_a_hand_made_table():
    result = t_interval([0.01, 0.03, 0.02])  # mean 0.02, SD 0.01, t(0.975, 2) = 4.3027
    assert result["mean"] == pytest.approx(0.02) and result["n_seeds"] == 3
    half = 4.302653 * 0.01 / np.sqrt(3)
    assert (result["ci_low"], result["ci_high"]) == pytest.approx((0.02 - half, 0.02 + half), abs=1e-6)
    five = t_interval([0.1, 0.2, 0.3, 0.4, 0.5])
    assert five["ci_high"] - five["mean"] == pytest.approx(scipy_stats.t.ppf(0.975, 4) * np.std([0.1, 0.2, 0.3, 0.4, 0.5], ddof=1) / np.sqrt(5))
    assert t_interval([0.05])["ci_low"] is None and t_interval([None, 0.05, float("nan")])["n_seeds"] == 1


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


def test_the_declared_contrasts():
    names = [c.name for c in declared_contrasts([50, 200], [0.0, 0.5, 1.0], [50], {50: 0.5})]
    assert names == ["real_data", "targeted_vs_none@50", "targeted_vs_none_chosen@50", "targeted_vs_random@50", "targeted_vs_real@50"]
    contrasts = {c.name: c for c in declared_contrasts([50, 200], [0.0, 0.5, 1.0], [50], {50: 0.5})}
    assert dict((k, w) for w, k in contrasts["real_data"].terms) == {("targeted", 200, 0.0): 1.0, ("targeted", 50, 0.0): -1.0}
    versus = contrasts["targeted_vs_real@50"].terms
    assert sum(w for w, _ in versus) == pytest.approx(0) and {k[0] for _, k in versus} == {"targeted", "real"}
    assert sum(w for w, _ in contrasts["targeted_vs_none@50"].terms) == pytest.approx(0)
    assert [v.name for v in seed_variants([50, 200], [0.0, 1.0], [50], ceiling=True)] == [
        "targeted/50-0", "targeted/200-0", "targeted/50-1", "random/50-1", "real/50-1", "ceiling"]


def test_gain_sentences_give_shares_and_call_a_gap_within_the_ceilings_interval_no_gap():
    import pandas as pd

    from graspaug.experiments.ap import gain_sentences

    table = pd.DataFrame([("targeted", 50, 0.0, 0.40, 0.02), ("targeted", 50, 1.0, 0.42, 0.02), ("targeted", 200, 0.0, 0.495, 0.01),
                          ("targeted", 200, 1.0, 0.50, 0.01), ("ceiling", 0, 0.0, 0.50, 0.01)],
                         columns=["pool", "base_size", "ratio", "test_ap", "test_ap_ci"])
    results = {"targeted_vs_none@50": {"mean": 0.02}, "targeted_vs_real@50": {"mean": -0.06}}  # real shapes: +0.08
    lines = gain_sentences(results, table, {50: 1.0, 200: 1.0}, [50], ceiling_shapes=600)
    assert "give 25% of the gain of the same number of real shapes" in lines[0]
    assert "1:1 closes 20% of the gap" in lines[1]  # (0.42 - 0.40) / (0.50 - 0.40)
    assert "no gap for augmentation to close" in lines[2] and "closes" not in lines[2]  # 0.005 < ±0.01: not "100%"
    assert gain_sentences(results, table, {50: 1.0}, [50], ceiling_shapes=None) == lines[:1]
    below = table.assign(test_ap=table.test_ap.where(table.pool != "ceiling", 0.30))
    assert "below 1:0" in gain_sentences(results, below, {50: 1.0}, [], ceiling_shapes=600)[0]
