"""Per-shape scores that pick the shapes to augment (paper Section III-B)."""

from __future__ import annotations

import numpy as np
from sklearn.neighbors import NearestNeighbors

_DISTANCE_FLOOR = 1e-10  # keeps D finite for duplicate latents (scikit-learn's LOF does the same)


def rarity(reference: np.ndarray, k: int, query: np.ndarray | None = None) -> np.ndarray:
    """Rarity R of each shape, the paper's eq. (3)-(4), from latents (M, d).

    ``D(O) = 1 / mean_{P ∈ N_k(O)} dist(O, P)`` (eq. 3, Euclidean, k nearest neighbours) and
    ``R(O) = mean_{P ∈ N_k(O)} D(P) / D(O)`` (eq. 4): about 1 inside a cluster, larger for
    shapes in sparse regions. With ``query`` (Q, d) the scores are of those points relative
    to ``reference`` (neighbours and their densities from ``reference`` only); without it,
    of the reference points themselves (a point is not its own neighbour).
    Returns (M,) or (Q,).
    """
    reference = np.asarray(reference, dtype=float)
    if len(reference) < 2:
        raise ValueError(f"rarity needs at least 2 reference shapes, got {len(reference)}")
    k = min(k, len(reference) - 1)
    knn = NearestNeighbors(n_neighbors=k).fit(reference)
    ref_dist, _ = knn.kneighbors()
    ref_density = 1.0 / np.maximum(ref_dist.mean(axis=1), _DISTANCE_FLOOR)  # eq. (3)
    if query is None:
        dist, neighbours = knn.kneighbors()
    else:
        dist, neighbours = knn.kneighbors(np.asarray(query, dtype=float), n_neighbors=k)
    density = 1.0 / np.maximum(dist.mean(axis=1), _DISTANCE_FLOOR)
    return ref_density[neighbours].mean(axis=1) / density  # eq. (4)


def graspness(success: np.ndarray, shape_index: np.ndarray, n_shapes: int) -> tuple[np.ndarray, np.ndarray]:
    """Graspness (share of successful grasps) and grasp count (n_shapes,) from per-grasp
    ``success`` (G,) bool and ``shape_index`` (G,) in [0, n_shapes). A shape without grasps has
    graspness 0: no grasp was found on it."""
    counts = np.bincount(shape_index, minlength=n_shapes)
    wins = np.bincount(shape_index, weights=np.asarray(success, dtype=float), minlength=n_shapes)
    return np.divide(wins, counts, out=np.zeros(n_shapes), where=counts > 0), counts
