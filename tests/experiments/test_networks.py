"""The GQ-CNN experiment's paired seeds: every network of a seed starts from the same weights."""

import torch

from graspaug.experiments.networks import initial_weights, seed_members, stream_seeds, weights_digest
from graspaug.nets.settings import GQCNNConfig


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
