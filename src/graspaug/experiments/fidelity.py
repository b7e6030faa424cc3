"""How close is a pool of shapes to real shapes, before any network trains on it?

Distribution distances between a pool and held-out real shapes, as 3D generative-model papers
report them (Achlioptas et al. 2018; Yang et al. 2019, PointFlow), on the Chamfer distance between
point clouds sampled from the meshes' surfaces:

* **coverage** (COV): the share of reference shapes that are the nearest reference shape of at
  least one pool shape (higher is better; a pool that covers the references' variety);
* **minimum matching distance** (MMD): the mean over reference shapes of the distance to their
  nearest pool shape (lower is better; fidelity);
* **1-NN accuracy** (1-NNA): leave-one-out accuracy of a 1-nearest-neighbour classifier telling
  pool from reference shapes in their union (0.5 is the ideal: the two sets are
  indistinguishable; 1.0: every shape's nearest neighbour is from its own set). It needs sets of
  equal size.

Chamfer distance here: the mean, over both clouds' points, of the distance to the nearest point
of the other cloud (m, not squared), the clouds centered on their centroids.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from scipy.spatial import cKDTree


def surface_cloud(mesh, n_points: int, rng: np.random.Generator) -> np.ndarray:
    """``n_points`` points (n_points, 3) m drawn uniformly by area on ``mesh``'s surface (a trimesh),
    centered on their centroid."""
    import trimesh

    points, _ = trimesh.sample.sample_surface(mesh, n_points, seed=rng)
    return points - points.mean(axis=0)


def chamfer_matrix(a: Sequence[np.ndarray], b: Sequence[np.ndarray]) -> np.ndarray:
    """Chamfer distance (m) between every cloud of ``a`` and every cloud of ``b`` (each (n, 3)):
    (len(a), len(b)), the mean of both directions' nearest-point distances."""
    trees_b = [cKDTree(cloud) for cloud in b]
    trees_a = [cKDTree(cloud) for cloud in a]
    out = np.empty((len(a), len(b)))
    for i, (cloud_a, tree_a) in enumerate(zip(a, trees_a)):
        for j, (cloud_b, tree_b) in enumerate(zip(b, trees_b)):
            out[i, j] = 0.5 * (tree_b.query(cloud_a)[0].mean() + tree_a.query(cloud_b)[0].mean())
    return out


def coverage_mmd(pool_to_reference: np.ndarray) -> tuple[float, float]:
    """Coverage and minimum matching distance (m) from the Chamfer distances (pool, reference)."""
    d = np.asarray(pool_to_reference, dtype=float)
    covered = np.unique(d.argmin(axis=1))
    return len(covered) / d.shape[1], float(d.min(axis=0).mean())


def one_nn_accuracy(pool_pool: np.ndarray, reference_reference: np.ndarray, pool_reference: np.ndarray) -> float:
    """Leave-one-out 1-NN accuracy on the union of a pool and a reference set of the same size, from
    their Chamfer distances within the pool (P, P), within the reference (P, P) and across (P, P)."""
    pp, rr, pr = (np.asarray(m, dtype=float) for m in (pool_pool, reference_reference, pool_reference))
    if not (pp.shape == rr.shape == pr.shape and pp.shape[0] == pp.shape[1]):
        raise ValueError(f"1-NNA needs square matrices of one size; got {pp.shape}, {rr.shape}, {pr.shape}")
    n = len(pp)
    full = np.block([[pp, pr], [pr.T, rr]])
    np.fill_diagonal(full, np.inf)
    nearest = full.argmin(axis=1)
    own = np.r_[np.zeros(n, bool), np.ones(n, bool)]
    return float((own[nearest] == own).mean())


def distribution_distances(pool: Sequence[np.ndarray], reference: Sequence[np.ndarray]) -> dict[str, float]:
    """``coverage``, ``mmd`` (m) and ``one_nna`` of a pool of clouds against reference clouds of the same count."""
    pr = chamfer_matrix(pool, reference)
    coverage, mmd = coverage_mmd(pr)
    one_nna = one_nn_accuracy(chamfer_matrix(pool, pool), chamfer_matrix(reference, reference), pr)
    return {"coverage": coverage, "mmd": mmd, "one_nna": one_nna}
