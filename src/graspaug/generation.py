"""Which shapes to generate: base sets, selection by score, neighbour pairs and the pool order
(paper Section III-C and the augmentation sets of Section IV-C/D).

A pool is a list of ``Candidate`` (parent pair + interpolation weight), ordered so that its
first ``round(R · B)`` entries are the augmentation set for ratio ``R``: sets for larger
ratios contain those for smaller ones.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from sklearn.neighbors import NearestNeighbors


@dataclass(frozen=True)
class Candidate:
    """One shape to generate: parents ``a``, ``b`` (indices into the base set), weight ``alpha``
    on ``b`` (z = (1 - α) z_a + α z_b), and what chose the pair (``rarity``, ``graspness``,
    ``random``)."""

    a: int
    b: int
    alpha: float
    selected_by: str


def nested_base_sets(shape_ids: np.ndarray, sizes: list[int], rng: np.random.Generator) -> dict[int, np.ndarray]:
    """Base sets of each size drawn from ``shape_ids`` (e.g. the train split): one seeded
    permutation, so each set is the first ``size`` of it and smaller sets lie inside larger ones."""
    if max(sizes) > len(shape_ids):
        raise ValueError(f"base size {max(sizes)} is larger than the {len(shape_ids)} shapes to draw from")
    order = rng.permutation(len(shape_ids))
    return {size: np.asarray(shape_ids)[order[:size]] for size in sizes}


def above_percentile(scores: np.ndarray, percentile: float) -> np.ndarray:
    """Indices of the scores strictly above their ``percentile``-th percentile (at least one)."""
    scores = np.asarray(scores, dtype=float)
    chosen = np.flatnonzero(scores > np.percentile(scores, percentile))
    return chosen if len(chosen) else np.array([int(np.argmax(scores))])


def neighbour_pairs(z: np.ndarray, first: int, extra: int) -> list[tuple[int, int]]:
    """Unordered pairs ``(i, j)``, ``i < j``, of each point with its ``first``-th to
    ``(first + extra)``-th nearest neighbours (Euclidean, 1 = nearest; ranks beyond the other
    points are skipped), in order of (neighbour rank, i) with duplicates dropped."""
    n = len(z)
    last = min(first + extra, n - 1)
    if n < 2 or first > last:
        return []
    _, idx = NearestNeighbors(n_neighbors=last).fit(z).kneighbors()
    pairs: dict[tuple[int, int], None] = {}
    for rank in range(first, last + 1):
        for i in range(n):
            j = int(idx[i, rank - 1])
            pairs.setdefault((min(i, j), max(i, j)), None)
    return list(pairs)


def targeted_candidates(z: np.ndarray, rarity: np.ndarray, graspness: np.ndarray, percentile: float, first: int, extra: int, alphas: list[float]) -> list[Candidate]:
    """The targeted pool's candidates, in pool order.

    Shapes above the ``percentile`` in rarity form one group, above it in graspness another;
    within each group, pairs of N-th to (N+K)-th nearest neighbours (latent space of the
    group). The two groups' lists (each: every pair at the first α, then every pair at the
    next α, …) are interleaved one by one; a pair and weight already taken is skipped."""
    lists = []
    for name, scores in (("rarity", rarity), ("graspness", graspness)):
        group = above_percentile(scores, percentile)
        pairs = [(int(group[i]), int(group[j])) for i, j in neighbour_pairs(z[group], first, extra)]
        lists.append([Candidate(a, b, float(alpha), name) for alpha in alphas for a, b in pairs])
    out: list[Candidate] = []
    seen: set[tuple[int, int, float]] = set()
    for k in range(max(len(lst) for lst in lists)):
        for lst in lists:
            if k < len(lst) and (lst[k].a, lst[k].b, lst[k].alpha) not in seen:
                seen.add((lst[k].a, lst[k].b, lst[k].alpha))
                out.append(lst[k])
    return out


def random_candidates(n_shapes: int, count: int, alphas: list[float], rng: np.random.Generator) -> list[Candidate]:
    """``count`` candidates from uniformly random distinct pairs of the base set (the paper's
    "random augmentation" baseline): the pairs in a seeded order, weights cycling through
    ``alphas``; a pair comes back (with the next weight) only after every pair was used."""
    all_pairs = [(i, j) for i in range(n_shapes) for j in range(i + 1, n_shapes)]
    if not all_pairs:
        return []
    order = rng.permutation(len(all_pairs))
    out = []
    for k in range(count):
        i, j = all_pairs[order[k % len(all_pairs)]]
        round_ = k // len(all_pairs)  # each later round shifts the weights by one
        out.append(Candidate(i, j, float(alphas[(k % len(all_pairs) + round_) % len(alphas)]), "random"))
    return out
