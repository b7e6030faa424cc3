"""Which shapes to generate: base sets, selection by score, neighbour pairs and the pool order
(paper Section III-C and the augmentation sets of Section IV-C/D).

A pool is an append-only stream of ``Candidate`` (parent pair + interpolation weight); the
kept ones, in stream order, make the pool, whose first ``ratio_count(R, B)`` shapes are the
augmentation set for ratio ``R``: sets for larger ratios contain those for smaller ones.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from typing import Protocol, TypeVar

import numpy as np
import pandas as pd
from sklearn.neighbors import NearestNeighbors

from graspaug.errors import DataError

EXTRA_ALPHAS = (0.4, 0.2, 0.1, 0.05)  # weights a targeted stream adds, in this order, when it runs dry


@dataclass(frozen=True)
class Candidate:
    """One shape to generate: parents ``a``, ``b`` (indices into the base set), weight ``alpha``
    on ``b`` (z = (1 - α) z_a + α z_b, so below 0.5 the child is closer to ``a``, the selected
    shape whose neighbour ``b`` is), and what chose the pair (``rarity``, ``graspness``, ``random``)."""

    a: int
    b: int
    alpha: float
    selected_by: str


def ratio_count(ratio: float, base_size: int) -> int:
    """Generated shapes in the augmentation set of ``ratio`` (generated : base) for a base set of
    ``base_size``: ``R · B`` rounded half up (1:0.5 of 25 shapes is 13)."""
    return math.floor(ratio * base_size + 0.5)


def pool_size(ratios: Sequence[float], base_size: int) -> int:
    """Shapes a pool needs so that every ratio's set is a prefix of it."""
    return max(ratio_count(r, base_size) for r in ratios)


def nested_base_sets(shape_ids: np.ndarray, sizes: list[int], rng: np.random.Generator) -> dict[int, np.ndarray]:
    """Base sets of each size drawn from ``shape_ids`` (e.g. the train split): one seeded
    permutation, so each set is the first ``size`` of it and smaller sets lie inside larger ones."""
    if max(sizes) > len(shape_ids):
        raise DataError(f"base size {max(sizes)} is larger than the {len(shape_ids)} shapes to draw from")
    order = rng.permutation(len(shape_ids))
    return {size: np.asarray(shape_ids)[order[:size]] for size in sizes}


BASE_SEED = 0xBA5E  # base sets: their own stream of the seed


def draw_base_sets(shapes: pd.DataFrame, sizes, seed: int) -> dict[int, np.ndarray]:
    """The base sets of every size in ``sizes``, drawn from the train split of ``shapes``
    (the ingested shape table) with the global ``seed``: what ``generate`` augments and what the
    GQ-CNN experiment's 1:0 networks train on, the same wherever they are drawn."""
    train_ids = shapes.shape_id[shapes.split == "train"].to_numpy()
    return nested_base_sets(train_ids, sorted(sizes), np.random.default_rng([seed, BASE_SEED]))


def above_percentile(scores: np.ndarray, percentile: float) -> np.ndarray:
    """Indices of the scores strictly above their ``percentile``-th percentile (at least one)."""
    scores = np.asarray(scores, dtype=float)
    chosen = np.flatnonzero(scores > np.percentile(scores, percentile))
    return chosen if len(chosen) else np.array([int(np.argmax(scores))])


def neighbour_pairs(
    z: np.ndarray, first: int, extra: int, anchors: Sequence[int] | None = None
) -> list[tuple[int, int]]:
    """Pairs ``(i, j)`` of each point ``i`` (every point, or only the ``anchors``, in their order)
    with its ``first``-th to ``(first + extra)``-th nearest neighbours ``j`` among all points
    (Euclidean, 1 = nearest; ranks beyond the other points are skipped), in order of (neighbour
    rank, i); a pair already met the other way round is dropped."""
    n = len(z)
    last = min(first + extra, n - 1)
    if n < 2 or first > last:
        return []
    _, idx = NearestNeighbors(n_neighbors=last).fit(z).kneighbors()
    seen: set[frozenset[int]] = set()
    pairs = []
    for rank in range(first, last + 1):
        for i in range(n) if anchors is None else anchors:
            j = int(idx[i, rank - 1])
            if frozenset((i, j)) not in seen:
                seen.add(frozenset((i, j)))
                pairs.append((i, j))
    return pairs


def targeted_candidates(
    z: np.ndarray,
    rarity: np.ndarray,
    graspness: np.ndarray,
    percentile: float,
    first: int,
    extra: int,
    alphas: Sequence[float],
) -> list[Candidate]:
    """Candidates from the shapes above the ``percentile`` in rarity (one group) and in
    graspness (another), each paired with its N-th to (N+K)-th nearest neighbours of its group
    in latent space. Each group's list holds every pair once per round, the weights cycling
    through ``alphas`` along the pairs and shifted by one each round (the random pool's schedule,
    so both pools use each weight equally often); the two lists are interleaved one by one; a
    pair and weight already taken is skipped."""
    lists = []
    for name, scores in (("rarity", rarity), ("graspness", graspness)):
        group = above_percentile(scores, percentile)
        pairs = [(int(group[i]), int(group[j])) for i, j in neighbour_pairs(z[group], first, extra)]
        lists.append(cycled(pairs, alphas, name))
    out: list[Candidate] = []
    seen: set[tuple[frozenset[int], float]] = set()
    for k in range(max(len(lst) for lst in lists)):
        for lst in lists:
            if k < len(lst) and (key := candidate_key(lst[k].a, lst[k].b, lst[k].alpha)) not in seen:
                seen.add(key)
                out.append(lst[k])
    return out


def candidate_key(a, b, alpha: float) -> tuple[frozenset, float]:
    """What makes two candidates the same shape: the unordered parents (indices or ids) and the weight."""
    return frozenset((a, b)), float(alpha)


class CandidateStream:
    """An append-only list of distinct candidates that a subclass grows on demand: what was
    handed out stays where it was, so a pool filled for more shapes starts with the same ones."""

    def __init__(self) -> None:
        self.items: list[Candidate] = []
        self.notes: list[str] = []  # how the stream was widened
        self._seen: set[tuple[frozenset[int], float]] = set()

    def _append(self, candidates: list[Candidate]) -> None:
        for c in candidates:
            key = candidate_key(c.a, c.b, c.alpha)
            if key not in self._seen:
                self._seen.add(key)
                self.items.append(c)

    def _grow(self, count: int) -> None:
        """Append candidates until there are ``count``, if the rule allows."""

    def take(self, start: int, count: int) -> list[Candidate]:
        """Candidates ``start .. start + count`` (fewer, or none, once the stream is exhausted)."""
        if len(self.items) < start + count:
            self._grow(start + count)
        return self.items[start : start + count]


class TargetedStream(CandidateStream):
    """The targeted pool's stream (:func:`targeted_candidates`). When it runs dry it widens,
    one step at a time, each noted: first the next weight of EXTRA_ALPHAS (near pairs stay
    near), then K by one while a group has neighbours that far, then the percentile down by 5."""

    def __init__(
        self,
        z: np.ndarray,
        rarity: np.ndarray,
        graspness: np.ndarray,
        percentile: float,
        first: int,
        extra: int,
        alphas: Sequence[float],
    ) -> None:
        super().__init__()
        self.z, self.rarity, self.graspness, self.first = z, rarity, graspness, first
        self.percentile, self.extra, self.alphas = float(percentile), extra, list(alphas)
        self._refill()

    def _refill(self) -> None:
        self._append(
            targeted_candidates(
                self.z, self.rarity, self.graspness, self.percentile, self.first, self.extra, self.alphas
            )
        )

    def _grow(self, count: int) -> None:
        while len(self.items) < count:
            largest_group = max(len(above_percentile(s, self.percentile)) for s in (self.rarity, self.graspness))
            extra_alphas = [a for a in EXTRA_ALPHAS if a not in self.alphas]
            if extra_alphas:
                self.alphas.append(extra_alphas[0])
                self.notes.append(f"alpha {extra_alphas[0]} added ({len(self.items)} candidates, {count} wanted)")
            elif self.first + self.extra < largest_group - 1:
                self.extra += 1
                self.notes.append(f"K widened to {self.extra} ({len(self.items)} candidates, {count} wanted)")
            elif self.percentile > 0:
                self.percentile = max(0.0, self.percentile - 5.0)
                self.notes.append(
                    f"percentile lowered to {self.percentile:g} ({len(self.items)} candidates, {count} wanted)"
                )
            else:
                return
            self._refill()


def cycled(pairs: Sequence[tuple[int, int]], alphas: Sequence[float], selected_by: str) -> list[Candidate]:
    """Every pair once per weight round: the weights cycle through ``alphas`` along the pairs,
    shifted by one each round, so each weight is used equally often (the schedule every pool shares)."""
    return [
        Candidate(a, b, float(alphas[(k + round_) % len(alphas)]), selected_by)
        for round_ in range(len(alphas))
        for k, (a, b) in enumerate(pairs)
    ]


class FailureStream(CandidateStream):
    """The lifelong loop's failure-targeted stream: each anchor (a training shape near an object
    the planner fails on, most failing first) paired with its ``first``-th to ``(first + extra)``-th
    nearest neighbours in latent space among all ``z``, the weights cycling as every pool's do
    (:func:`cycled`; α on the neighbour, so below 0.5 a child stays nearer its anchor). When it
    runs dry it widens, each step noted: the next weight of EXTRA_ALPHAS, then K by one."""

    def __init__(self, z: np.ndarray, anchors: Sequence[int], first: int, extra: int, alphas: Sequence[float]) -> None:
        super().__init__()
        self.z, self.anchors, self.first, self.extra, self.alphas = z, list(anchors), first, extra, list(alphas)
        self._refill()

    def _refill(self) -> None:
        self._append(cycled(neighbour_pairs(self.z, self.first, self.extra, self.anchors), self.alphas, "failure"))

    def _grow(self, count: int) -> None:
        while len(self.items) < count:
            extra_alphas = [a for a in EXTRA_ALPHAS if a not in self.alphas]
            if extra_alphas:
                self.alphas.append(extra_alphas[0])
                self.notes.append(f"alpha {extra_alphas[0]} added ({len(self.items)} candidates, {count} wanted)")
            elif self.first + self.extra < len(self.z) - 1:
                self.extra += 1
                self.notes.append(f"K widened to {self.extra} ({len(self.items)} candidates, {count} wanted)")
            else:
                return
            self._refill()


class RandomStream(CandidateStream):
    """The random pool's stream (the paper's "random augmentation" baseline): every distinct
    pair of the base set in a seeded order, weights cycling through ``alphas``; after all
    pairs, each pair again with the next weight, until every pair has had every weight."""

    def __init__(self, n_shapes: int, alphas: Sequence[float], rng: np.random.Generator) -> None:
        super().__init__()
        pairs = [(i, j) for i in range(n_shapes) for j in range(i + 1, n_shapes)]
        order = rng.permutation(len(pairs))
        for round_ in range(len(alphas)):
            self._append(
                [Candidate(*pairs[p], float(alphas[(k + round_) % len(alphas)]), "random") for k, p in enumerate(order)]
            )


class ReconStream(CandidateStream):
    """The ``recon`` pool's stream: shape k of a list of real shapes reconstructed alone
    (parents k and k, weight 0), in the list's order; the pool decodes each once (:func:`decode_each`), so a
    rejected decode leaves a gap rather than taking the next shape."""

    def __init__(self, n_shapes: int) -> None:
        super().__init__()
        self._append([Candidate(k, k, 0.0, "recon") for k in range(n_shapes)])


class PrimitiveStream(CandidateStream):
    """The ``primitives`` pool's stream: assembly k of ``n_shapes`` (parents k and k, weight 0), in order, so a
    rejected assembly is replaced by the next one. No real shape is its parent."""

    def __init__(self, n_shapes: int) -> None:
        super().__init__()
        self._append([Candidate(k, k, 0.0, "primitives") for k in range(n_shapes)])


class ProceduralStream(CandidateStream):
    """The ``procedural`` pool's stream: object k of a shuffled procedural corpus (parents k and k, weight 0), in
    order, so a rejected object is replaced by the next one. No shape of the experiment's corpus is its parent."""

    def __init__(self, n_shapes: int) -> None:
        super().__init__()
        self._append([Candidate(k, k, 0.0, "procedural") for k in range(n_shapes)])


class FollowStream(CandidateStream):
    """Another pool's candidates for a control pool (the ``blend`` pool follows the targeted one):
    ``first`` (that pool's kept candidates, in order: the same pairs and weights) then the rest of
    its ``stream`` in order, so a failure here is replaced by that pool's next candidate. Candidates
    whose pair and weight are in ``used`` (:func:`candidate_key`) are skipped: a later round of the
    lifelong loop does not make an earlier round's shape again. Its notes are ``stream``'s."""

    def __init__(
        self, first: Sequence[Candidate], stream: CandidateStream, used: Iterable[tuple[frozenset, float]] = ()
    ) -> None:
        super().__init__()
        self.stream, self._read, self.notes = stream, 0, stream.notes
        self._seen.update(used)
        self._append(list(first))

    def _grow(self, count: int) -> None:
        while len(self.items) < count:
            batch = self.stream.take(self._read, count - len(self.items))
            if not batch:
                return
            self._read += len(batch)
            self._append(batch)


class HasReason(Protocol):
    reason: str | None


D = TypeVar("D", bound=HasReason)


class PoolExhausted(RuntimeError):
    """A pool could not be filled: every candidate the stream allows was tried."""


def fill_pool(
    stream: CandidateStream, needed: int, run_batch: Callable[[list[Candidate]], list[D]]
) -> tuple[list[D], list[D]]:
    """Try the stream's candidates in order until ``needed`` are kept (``reason`` None);
    ``run_batch`` decodes a batch. Returns the kept and the rejected, in stream order; raises
    :class:`PoolExhausted` if the stream ends first."""
    kept: list[D] = []
    rejected: list[D] = []
    while len(kept) < needed:
        tried = len(kept) + len(rejected)
        batch = stream.take(tried, needed - len(kept))
        if not batch:
            raise PoolExhausted(
                f"only {len(kept)} of {needed} shapes after {tried} candidates; no more pairs or weights to try"
            )
        for outcome in run_batch(batch):
            (rejected if outcome.reason else kept).append(outcome)
    return kept, rejected


def decode_each(
    stream: CandidateStream, count: int, run_batch: Callable[[list[Candidate]], list[D]]
) -> tuple[list[D], list[D]]:
    """Decode the stream's first ``count`` candidates once each, with no replacement: the kept (``reason`` None) and
    the rejected, in stream order. A pool whose shape k stands for shape k of a list (the ``recon`` pool: the real
    pool's extra shapes) keeps its failures as gaps instead of taking the next shape, so it is the same shapes as
    that list's first ``count`` less the ones that did not mesh."""
    kept: list[D] = []
    rejected: list[D] = []
    for outcome in run_batch(stream.take(0, count)) if count else []:
        (rejected if outcome.reason else kept).append(outcome)
    return kept, rejected


@dataclass(frozen=True)
class Decoded:
    """One candidate's outcome: the cleaned grid (bit-packed, R³ bits) and, if kept, its mesh (m)
    or why it was rejected."""

    candidate: Candidate
    packed_grid: np.ndarray
    mesh: object | None  # trimesh.Trimesh
    reason: str | None
