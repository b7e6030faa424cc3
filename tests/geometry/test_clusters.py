import numpy as np

from graspaug.geometry.clusters import largest_cluster, outlier_percentage


def test_outliers_are_the_voxels_outside_the_largest_piece():
    g = np.zeros((16, 16, 16), dtype=bool)
    g[2:5, 2:5, 2:5] = True  # 27 voxels
    g[10, 10, 10] = g[12, 3, 14] = g[14, 14, 1] = True  # 3 isolated voxels
    assert outlier_percentage(g) == 10.0
    assert largest_cluster(g).sum() == 27


def test_diagonal_neighbours_are_one_piece_but_a_gap_is_not():
    g = np.zeros((8, 8, 8), dtype=bool)
    g[1, 1, 1] = g[2, 2, 2] = g[3, 3, 3] = True  # corner-to-corner chain: 26-connected
    assert outlier_percentage(g) == 0.0
    g[5, 3, 3] = True  # two voxels away from the chain
    assert outlier_percentage(g) == 25.0


def test_empty_grid_has_no_outlier_percentage():
    assert np.isnan(outlier_percentage(np.zeros((4, 4, 4), dtype=bool)))
