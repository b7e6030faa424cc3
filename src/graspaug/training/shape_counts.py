"""How many shapes the GQ-CNN experiment's settings need of a corpus, and the one line that says a corpus is too small.

The train split holds, one after the other: the largest base set (``generate.base_sizes``; the smaller ones lie inside
it), ``gqcnn.val_shapes`` validation shapes outside every base set, and the real pool, the rest in a seeded order
(:func:`graspaug.training.gqcnn_data.experiment_split`). Of the real pool, the ``real`` network at (B, R) takes the
first round(R × B) shapes, the ``recon`` pool decodes those same shapes, the fidelity stage compares at least 2 of
them with real shapes, and the lifelong loop's real arm takes ``lifelong.shapes_per_round`` more each round. The test
split holds the GQ-CNN test set (at least 1 shape) and the fidelity stage's reference (at least 2). The rarity of
eq. (3)-(4) asks for no more: it needs 2 shapes, and its ``score.k`` neighbours are capped at the shapes less one.

:func:`shape_count_problem` is what the ``split`` stage checks, where the count is first known, so that a corpus too
small for the settings stops there (exit 2, one line) and not stages later, after the AutoEncoder, the grasps and the
renders.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

from graspaug.augment.candidates import ratio_count
from graspaug.training.variants import Variant

REAL_POOL_TAKERS = ("real", "recon")
"""Networks that take the real pool's first round(R × B) shapes: ``real`` trains on them, ``recon`` on their decodes."""
FIDELITY_SHAPES = 2
"""Shapes the fidelity stage needs of each pool and of its reference (test) shapes."""


def n_test_shapes(n: int, test_fraction: float) -> int:
    """Test shapes among ``n`` shapes (none a duplicate) at ``test_fraction``, as
    :func:`graspaug.augment.corpus.assign_split` draws them: round(test_fraction × n)."""
    return int(round(test_fraction * n))


@dataclass(frozen=True)
class ShapeNeeds:
    """The shapes a set of settings needs, by role.

    base : int — the largest base set (the largest of ``generate.base_sizes``)
    validation : int — ``gqcnn.val_shapes``
    real : int — real-pool shapes its most demanding user takes, ``real_for`` (0 and "" with none)
    test : int — test shapes
    """

    base: int
    validation: int
    real: int
    real_for: str
    test: int

    @property
    def train(self) -> int:
        """Train shapes: the largest base set, validation and the real pool, which do not overlap."""
        return self.base + self.validation + self.real

    def kept(self, test_fraction: float) -> int:
        """The fewest shapes (none a duplicate) whose split at ``test_fraction`` holds :attr:`train` train and
        :attr:`test` test shapes."""
        n = self.train
        while n - n_test_shapes(n, test_fraction) < self.train or n_test_shapes(n, test_fraction) < self.test:
            n += 1
        return n


def shape_needs(
    base_sizes: Iterable[int],
    val_shapes: int,
    variants: Iterable[Variant],
    pools: Iterable[str],
    augment_base_sizes: Iterable[int],
    lifelong_real: int = 0,
) -> ShapeNeeds:
    """The :class:`ShapeNeeds` of ``base_sizes`` (``generate.base_sizes``), ``val_shapes`` (``gqcnn.val_shapes``), a
    training seed's ``variants`` (:func:`graspaug.training.variants.seed_networks`), ``pools`` (``gqcnn.pools``),
    ``augment_base_sizes`` (``gqcnn.augment_base_sizes``: the fidelity stage runs at each) and ``lifelong_real``, the
    real-pool shapes the lifelong loop's real arm adds by its last round (0: no rounds)."""
    takers = [(ratio_count(v.ratio, v.base_size), v.name) for v in variants if v.pool in REAL_POOL_TAKERS]
    fidelity = list(augment_base_sizes)
    compared = [p for p in REAL_POOL_TAKERS if p in set(pools)]
    if fidelity and compared:
        takers.append((FIDELITY_SHAPES, f"fidelity of {' and '.join(compared)}"))
    if lifelong_real:
        takers.append((lifelong_real, "lifelong's real arm"))
    real, real_for = max(takers, key=lambda taker: taker[0], default=(0, ""))
    return ShapeNeeds(max(base_sizes), val_shapes, real, real_for, FIDELITY_SHAPES if fidelity else 1)


def shape_count_problem(
    n_train: int, n_test: int, needs: ShapeNeeds, test_fraction: float, counted: str = "kept by ingest"
) -> str | None:
    """Why ``n_train`` train and ``n_test`` test shapes (split at ``test_fraction``, ``ingest.test_fraction``) are
    too few for ``needs``: one line with the counts, the settings that ask for more and what to change; or None.
    ``counted`` says what the shapes counted are."""
    if n_train >= needs.train and n_test >= needs.test:
        return None
    real = f" + {needs.real} for the real pool ({needs.real_for})" if needs.real else ""
    least = needs.kept(test_fraction)
    return (
        f"too few shapes: {n_train + n_test} {counted} ({n_train} train, {n_test} test at ingest.test_fraction "
        f"{test_fraction:g}), but these settings need {needs.train} train (generate.base_sizes up to {needs.base} + "
        f"gqcnn.val_shapes {needs.validation}{real}) and {needs.test} test shapes, at least {least} in all: add "
        f"{max(least - n_train - n_test, 1)} or more shapes, or lower generate.base_sizes, gqcnn.val_shapes or what "
        "the real pool must give (generate.ratios, gqcnn.pools, gqcnn.augment_base_sizes)"
    )
