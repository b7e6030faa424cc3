"""Base sets, selection, neighbour pairs and the pool order of the generate stage."""
import numpy as np
import pytest

from graspaug.generation import above_percentile, nested_base_sets, neighbour_pairs, random_candidates, targeted_candidates

# Points on a line at 0, 1, 3, 7, 12, 18: no ties, so every point's neighbour ranks are clear:
# 0: 1 2 3 4 5 | 1: 0 2 3 4 5 | 2: 1 0 3 4 5 | 3: 2 4 1 0 5 | 4: 3 5 2 1 0 | 5: 4 3 2 1 0
LINE = np.array([[0.0], [1.0], [3.0], [7.0], [12.0], [18.0]])


def test_neighbour_pairs_are_exactly_the_nth_to_n_plus_kth():
    assert neighbour_pairs(LINE, 1, 0) == [(0, 1), (1, 2), (2, 3), (3, 4), (4, 5)]
    # rank 2: 0-2 1-2 (2-0) 3-4 4-5 3-5, then rank 3: 0-3 1-3 2-3 (3-1) 2-4 2-5
    assert neighbour_pairs(LINE, 2, 1) == [(0, 2), (1, 2), (3, 4), (4, 5), (3, 5), (0, 3), (1, 3), (2, 3), (2, 4), (2, 5)]
    assert neighbour_pairs(LINE, 5, 3) == [(0, 5), (1, 5), (2, 5), (3, 5), (0, 4)]  # only 5 others: rank 5 is the last
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
    assert by == [
        ("rarity", 3, 4, 0.5), ("graspness", 0, 1, 0.5), ("rarity", 4, 5, 0.5), ("graspness", 1, 2, 0.5),
        ("rarity", 3, 4, 0.3), ("graspness", 0, 1, 0.3), ("rarity", 4, 5, 0.3), ("graspness", 1, 2, 0.3),
    ]
    # a shape in both groups: its pairs are not generated twice
    both = targeted_candidates(z, rare, rare, 50, 1, 0, [0.5])
    assert [(c.selected_by, c.a, c.b) for c in both] == [("rarity", 3, 4), ("rarity", 4, 5)]


def test_random_candidates_are_seeded_and_prefix_stable():
    a = random_candidates(6, 40, [0.5, 0.3], np.random.default_rng(1))
    b = random_candidates(6, 10, [0.5, 0.3], np.random.default_rng(1))
    assert a[:10] == b
    pairs = [(c.a, c.b) for c in a[:15]]
    assert len(set(pairs)) == 15 and all(i < j for i, j in pairs)  # every pair once before any repeats
    assert len({(c.a, c.b, c.alpha) for c in a[:30]}) == 30  # a repeated pair gets the other weight
