"""Rarity (eq. 3-4) against scikit-learn's LOF, and graspness."""

import numpy as np
import pytest
from scipy.stats import spearmanr
from sklearn.neighbors import LocalOutlierFactor

from graspaug.augment.scores import graspness, rarity


def clusters(seed):
    rng = np.random.default_rng(seed)
    return np.concatenate([rng.normal(0, 1, (150, 16)), rng.normal(5, 0.4, (100, 16)), rng.normal(0, 3, (30, 16))])


@pytest.mark.parametrize("k", [5, 20])
def test_rarity_ranks_like_sklearn_lof(k):
    z = clusters(0)
    lof = -LocalOutlierFactor(n_neighbors=k).fit(z).negative_outlier_factor_
    assert spearmanr(rarity(z, k), lof).statistic >= 0.9


def test_planted_far_point_is_the_rarest():
    z = clusters(1)
    z = np.concatenate([z, np.full((1, 16), 30.0)])
    r = rarity(z, 20)
    assert np.argmax(r) == len(z) - 1
    assert np.median(r[:150]) == pytest.approx(1.0, abs=0.15)  # inside a cluster R ≈ 1


def test_rarity_by_hand_on_a_line():
    """Points 0, 1, 2, 10 with k = 1: neighbour distances 1, 1, 1, 8, so D = 1, 1, 1, 1/8;
    R = D(neighbour) / D(self) = 1, 1, 1, 8."""
    z = np.array([[0.0], [1.0], [2.0], [10.0]])
    np.testing.assert_allclose(rarity(z, 1), [1, 1, 1, 8])
    # a query at 12 relative to them: neighbour 10 (D = 1/8), own D = 1/2 -> R = 0.25
    np.testing.assert_allclose(rarity(z, 1, query=np.array([[12.0]])), [0.25])


def test_duplicates_and_too_few_shapes():
    z = np.zeros((5, 3))
    assert np.all(np.isfinite(rarity(z, 3)))
    with pytest.raises(ValueError, match="at least 2"):
        rarity(z[:1], 3)


def test_graspness_counts_shapes_without_grasps():
    share, counts = graspness(np.array([True, False, True, True]), np.array([0, 0, 2, 2]), 3)
    np.testing.assert_allclose(share, [0.5, 0.0, 1.0])
    np.testing.assert_array_equal(counts, [2, 0, 2])
