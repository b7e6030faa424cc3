"""The GQ-CNN experiment's paired seeds: every network of a seed starts from the same weights."""

import torch

from graspaug.nets.settings import GQCNNConfig
from graspaug.training.networks import initial_weights, seed_headline, seed_members, stream_seeds, weights_digest


def test_the_networks_of_a_seed_share_initial_weights_and_seeds_differ():
    config = GQCNNConfig(filters=4, fc=8, pose_fc=4)
    first = initial_weights(config, stream_seeds(0, 1)[0])
    torch.manual_seed(123)  # whatever ran before does not matter
    again = initial_weights(config, stream_seeds(0, 1)[0])
    other = initial_weights(config, stream_seeds(0, 2)[0])
    assert weights_digest(first) == weights_digest(again) != weights_digest(other)
    assert all(torch.equal(first[k], again[k]) for k in first)
    # init and noise streams never collide
    assert len({*stream_seeds(0, 1), *stream_seeds(0, 2), *stream_seeds(1, 1)}) == 6


def test_members_of_a_seed_start_apart_and_member_zero_is_the_seeds_own_network():
    config = GQCNNConfig(filters=4, fc=8, pose_fc=4)
    inits, noise_seeds = seed_members(config, 0, 1, 3)
    assert (
        weights_digest(inits[0]) == weights_digest(initial_weights(config, stream_seeds(0, 1)[0]))
        and noise_seeds[0] == stream_seeds(0, 1)[1]
    )
    # distinct, reproducible
    assert len({weights_digest(w) for w in inits}) == 3 and seed_members(config, 0, 1, 3)[1] == noise_seeds
    streams = {s for seed in range(4) for m in range(8) for s in stream_seeds(0, seed, m)}
    assert len(streams) == 4 * 8 * 2  # no member's stream is another seed's or member's


def _summary(pool, base, ratio, val_ap, test_ap):
    return {
        "pool": pool,
        "base_size": base,
        "ratio": ratio,
        "train": {"datapoints": 100, "steps": 20, "best_step": 10},
        "validation": {"ap": val_ap},
        "test": {"ap": test_ap},
        "samples_per_second": 50.0 if pool == "ceiling" else 30.0,
        "threads": 2,
        "train_seconds": 1.26,
    }


def test_a_seeds_lines_timing_and_split_files(tmp_path):
    import json

    import numpy as np

    from graspaug.training.gqcnn_data import experiment_split
    from graspaug.training.networks import result_lines, save_seed_split, seed_timing

    results = [_summary("targeted", 50, 1.5, 0.5, None), _summary("ceiling", 0, 0.0, 0.61234, 0.7)]
    assert result_lines(results) == [
        "ceiling 0-0: 100 datapoints, 20 steps (kept 10); validation AP 0.6123, test AP 0.7000",
        "targeted 50-1.5: 100 datapoints, 20 steps (kept 10); validation AP 0.5000, test AP nan",
    ]
    timing = seed_timing(results, 12.345)
    assert timing["seconds"] == 12.3 and timing["networks"] == 2 and timing["samples_per_second_median"] == 40.0
    assert timing["train_seconds"] == {"targeted/50-1.5": 1.3, "ceiling/0-0": 1.3}
    assert timing["threads"] == 2  # the torch threads a network trained with

    split = experiment_split([f"s{i}" for i in range(6)], {2: ["s0", "s1"]}, 2, seed=0)
    save_seed_split(tmp_path, split, np.arange(3), np.arange(2))
    assert np.load(tmp_path / "test_rows.npy").tolist() == [0, 1, 2]
    assert np.load(tmp_path / "val_rows.npy").tolist() == [0, 1]
    assert json.loads((tmp_path / "split.json").read_text())["base"] == {"2": ["s0", "s1"]}


def test_a_seeds_metrics_are_the_mean_aps_of_its_networks():
    row = {"test_roc_auc": 0.9, "datapoints": 10, "steps": 5, "best_step": {"m0": 5, "m1": 3}}
    table = {
        "targeted": {"50": {"0": {**row, "val_ap": 0.4, "test_ap": 0.5}, "1": {**row, "val_ap": None, "test_ap": 0.6}}},
        "ceiling": {"all": {"-": {**row, "val_ap": 0.6, "test_ap": 0.7}}},
    }
    assert seed_headline(table) == {"test_ap": 0.6, "val_ap": 0.5}  # a network without a value is left out
    assert seed_headline({}) == {"test_ap": None, "val_ap": None}
