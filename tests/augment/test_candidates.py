"""Base sets, selection, neighbour pairs and the pool order of the generate stage."""

from dataclasses import dataclass

import numpy as np
import pandas as pd
import pytest

from graspaug.augment.candidates import (
    Candidate,
    PoolExhausted,
    RandomStream,
    TargetedStream,
    above_percentile,
    fill_pool,
    neighbour_pairs,
    nested_base_sets,
    pool_size,
    ratio_count,
    targeted_candidates,
)
from graspaug.augment.pool_tables import generate_headline

# Points on a line at 0, 1, 3, 7, 12, 18: no ties, so every point's neighbour ranks are clear:
# 0: 1 2 3 4 5 | 1: 0 2 3 4 5 | 2: 1 0 3 4 5 | 3: 2 4 1 0 5 | 4: 3 5 2 1 0 | 5: 4 3 2 1 0
LINE = np.array([[0.0], [1.0], [3.0], [7.0], [12.0], [18.0]])


def test_neighbour_pairs_are_exactly_the_nth_to_n_plus_kth():
    # (shape, its neighbour); a pair met the other way round before is dropped
    assert neighbour_pairs(LINE, 1, 0) == [(0, 1), (2, 1), (3, 2), (4, 3), (5, 4)]
    # rank 2: 0-2 1-2 (2-0) 3-4 4-5 5-3, then rank 3: 0-3 1-3 2-3 (3-1) 4-2 5-2
    assert neighbour_pairs(LINE, 2, 1) == [
        (0, 2),
        (1, 2),
        (3, 4),
        (4, 5),
        (5, 3),
        (0, 3),
        (1, 3),
        (2, 3),
        (4, 2),
        (5, 2),
    ]
    assert neighbour_pairs(LINE, 5, 3) == [(0, 5), (1, 5), (2, 5), (3, 5), (4, 0)]  # only 5 others: rank 5 is the last
    assert neighbour_pairs(LINE[:1], 1, 2) == []


def test_above_percentile_keeps_the_top_quarter():
    scores = np.arange(20.0)
    np.testing.assert_array_equal(above_percentile(scores, 75), [15, 16, 17, 18, 19])
    np.testing.assert_array_equal(above_percentile(np.ones(5), 75), [0])  # ties: still one shape


def test_base_sets_are_nested_and_seeded():
    ids = np.array([f"s{i:03d}" for i in range(300)])
    sets = nested_base_sets(ids, [50, 100, 200], np.random.default_rng(0))
    assert set(sets[50]) <= set(sets[100]) <= set(sets[200])
    assert [len(sets[b]) for b in (50, 100, 200)] == [50, 100, 200]
    again = nested_base_sets(ids, [200, 50], np.random.default_rng(0))
    np.testing.assert_array_equal(again[50], sets[50])  # the other sizes do not change a set
    with pytest.raises(ValueError, match="larger than"):
        nested_base_sets(ids[:10], [50], np.random.default_rng(0))


def test_targeted_candidates_interleave_groups_and_weights():
    z = LINE
    rare = np.array([0, 0, 0, 1, 2, 3.0])  # top half: 3, 4, 5
    graspable = np.array([3, 2, 1, 0, 0, 0.0])  # top half: 0, 1, 2
    cands = targeted_candidates(z, rare, graspable, 50, 1, 0, [0.5, 0.3])
    by = [(c.selected_by, c.a, c.b, c.alpha) for c in cands]
    assert by == [  # weights cycle along each group's pairs, shifted by one each round
        ("rarity", 3, 4, 0.5),
        ("graspness", 0, 1, 0.5),
        ("rarity", 5, 4, 0.3),
        ("graspness", 2, 1, 0.3),
        ("rarity", 3, 4, 0.3),
        ("graspness", 0, 1, 0.3),
        ("rarity", 5, 4, 0.5),
        ("graspness", 2, 1, 0.5),
    ]
    # a shape in both groups: its pairs are not generated twice
    both = targeted_candidates(z, rare, rare, 50, 1, 0, [0.5])
    assert [(c.selected_by, c.a, c.b) for c in both] == [("rarity", 3, 4), ("rarity", 5, 4)]


def test_targeted_and_random_pools_use_each_weight_equally_often():
    """The two streams share one weight schedule: in every prefix each weight of ``alphas`` comes up as often as
    the others, within one (per group for the targeted stream, so within two in all)."""
    from collections import Counter

    rng = np.random.default_rng(3)
    z, rare, grasp = rng.normal(size=(40, 4)), rng.random(40), rng.random(40)
    alphas = [0.5, 0.3]
    targeted = TargetedStream(z, rare, grasp, 75, 2, 3, alphas)
    random = RandomStream(40, alphas, np.random.default_rng(0))
    for n in (10, 25, 50):
        for stream, slack in ((targeted, 2), (random, 1)):
            counts = Counter(c.alpha for c in stream.take(0, n))
            assert set(counts) == set(alphas) and max(counts.values()) - min(counts.values()) <= slack, (n, counts)


def test_a_pools_makeup_counts_parents_and_weights():
    from graspaug.augment.pool_tables import pool_makeup

    rows = pd.DataFrame({"parent_a": ["s1", "s1", "s2"], "parent_b": ["s2", "s3", "s3"], "alpha": [0.5, 0.3, 0.5]})
    assert pool_makeup(rows) == {"distinct_parents": 3, "alphas": {"0.3": 1, "0.5": 2}}


def test_random_stream_is_seeded_distinct_and_finite():
    a = RandomStream(6, [0.5, 0.3], np.random.default_rng(1))
    b = RandomStream(6, [0.5, 0.3], np.random.default_rng(1))
    assert a.items == b.items and len(a.items) == 15 * 2  # every pair, with every weight, once
    assert len({(frozenset((c.a, c.b)), c.alpha) for c in a.items}) == 30
    assert len({frozenset((c.a, c.b)) for c in a.items[:15]}) == 15  # all pairs before any repeats
    assert a.take(28, 10) == a.items[28:] and a.take(30, 5) == []


def test_ratio_sets_are_prefixes_of_the_pool():
    assert [ratio_count(r, 25) for r in (0, 0.5, 1, 1.5, 2)] == [0, 13, 25, 38, 50]
    assert pool_size([0.0, 0.5, 1.5], 25) == 38 and all(ratio_count(r, 25) <= 38 for r in (0.0, 0.5, 1.5))


@dataclass
class Outcome:
    candidate: Candidate
    reason: str | None


def every_third_rejected(batch):
    """A stand-in decoder for the pool logic: rejects the candidates whose weight-and-pair hash says so."""
    return [Outcome(c, "empty decode" if (c.a * 7 + c.b * 3 + int(c.alpha * 10)) % 3 == 0 else None) for c in batch]


def test_fill_pool_replaces_rejects_widens_and_keeps_prefixes():
    rng = np.random.default_rng(4)
    z, rare, grasp = rng.normal(size=(12, 4)), rng.random(12), rng.random(12)

    def pool(needed):
        stream = TargetedStream(z, rare, grasp, 75, 1, 0, [0.5])
        kept, rejected = fill_pool(stream, needed, every_third_rejected)
        return stream, kept, rejected

    small_stream, small, _ = pool(4)
    stream, kept, rejected = pool(30)
    assert len(kept) == 30 and rejected and all(o.reason for o in rejected)
    assert stream.notes and stream.notes[0].startswith("alpha 0.4 added")  # it had to widen, and said so
    tried = [o.candidate for o in kept + rejected]
    assert len({(frozenset((c.a, c.b)), c.alpha) for c in tried}) == len(tried)  # nothing decoded twice
    assert [o.candidate for o in kept[:4]] == [o.candidate for o in small]  # the smaller pool is a prefix
    assert stream.items[: len(small_stream.items)] == small_stream.items  # and so is the stream
    with pytest.raises(PoolExhausted, match="no more pairs or weights"):
        fill_pool(RandomStream(3, [0.5], np.random.default_rng(0)), 5, every_third_rejected)


def test_the_generate_headline_counts_both_pools():
    summary = {"targeted": {"kept": 50, "tried": 50, "alphas_used": [0.5]}, "random": {"kept": 50, "tried": 51}}
    assert generate_headline(summary) == {"shapes": 100, "kept": round(100 / 101, 4)}
