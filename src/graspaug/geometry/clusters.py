"""Connected pieces of voxel grids, by DBSCAN as in the paper's critic study (Section IV-B)."""

from __future__ import annotations

import numpy as np

# neighbour radius: one voxel diagonal (26-connectivity), a hair more for float safety
VOXEL_DIAGONAL = float(np.sqrt(3.0)) + 1e-6


def largest_cluster(occupancy: np.ndarray) -> np.ndarray:
    """(R, R, R) bool → same-shape bool mask of the largest DBSCAN cluster of occupied voxels.

    DBSCAN (scikit-learn) on the occupied voxels' integer coordinates with ``eps`` one
    voxel diagonal and ``min_samples=1``: every occupied voxel is a core point, so the
    clusters are the 26-connected pieces.
    """
    from sklearn.cluster import DBSCAN

    occupancy = np.asarray(occupancy, dtype=bool)
    points = np.argwhere(occupancy)
    mask = np.zeros_like(occupancy)
    if len(points) == 0:
        return mask
    labels = DBSCAN(eps=VOXEL_DIAGONAL, min_samples=1).fit_predict(points)
    biggest = np.bincount(labels).argmax()
    mask[tuple(points[labels == biggest].T)] = True
    return mask


def outlier_percentage(occupancy: np.ndarray) -> float:
    """Percentage of occupied voxels outside the largest cluster (NaN for an empty grid)."""
    occupied = int(np.count_nonzero(occupancy))
    if occupied == 0:
        return float("nan")
    return 100.0 * (occupied - int(largest_cluster(occupancy).sum())) / occupied
