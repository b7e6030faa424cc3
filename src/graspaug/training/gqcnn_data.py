"""The GQ-CNN experiment's datasets, object-wise: which train-split shapes validate, which form
the `real` pool and the ceiling, and the datapoints of every training set, the validation set
and the test set, read from the rendered corpora (GQ-CNN dataset folders, :mod:`graspaug.io.gqcnn`).

Datapoints are :class:`~graspaug.training.gqcnn.GraspArrays`. A network is a
:class:`~graspaug.training.variants.Variant`:

* ``targeted`` / ``random`` at base size B and ratio R: the datapoints of the B base shapes
  (drawn from the shape table as ``generate`` draws them) in the original corpus plus those of
  the first round(R × B) shapes of that pool in the corpus of base size B's generated shapes;
* ``real`` at B and R: the base shapes plus the first round(R × B) shapes of the real pool
  (more train-split shapes, in a seeded order);
* ``ceiling``: every train-split shape outside validation;
* ``balanced`` at B and R: the B base shapes alone, its batches drawn at the positive share of targeted at (B, R)
  (``target_positive_share`` of its info; :class:`~graspaug.training.gqcnn.BatchSampler`);
* ``views`` at B and R: the B base shapes plus as many datapoints as targeted at (B, R) adds, drawn in a seeded
  order from the extra camera views of the base shapes (the ``views`` corpus, :attr:`Corpora.views`).

Validation is a fixed, seeded set of train-split shapes that lie in no base set and in no
pool: the same for every variant, pool and training seed, never trained on. Ratio 0 of any
pool is the base set alone (the ``targeted`` network).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from graspaug.augment.candidates import draw_base_sets, ratio_count
from graspaug.errors import DataError
from graspaug.io.gqcnn import GraspImages
from graspaug.io.tables import read_table
from graspaug.rng import shape_rng
from graspaug.training.gqcnn import GraspArrays
from graspaug.training.settings import SAMPLED_POOLS
from graspaug.training.variants import Variant


@dataclass(frozen=True)
class Corpora:
    """The rendered GQ-CNN dataset folders the networks read: ``original`` (the ingested shapes)
    and ``generated``, base size → the folder of that base set's generated shapes (both pools); ``views``: the
    original shapes rendered from extra camera views (the ``views`` networks), or None."""

    original: Path
    generated: Mapping[int, Path] = field(default_factory=dict)
    views: Path | None = None


@dataclass(frozen=True)
class ExperimentSplit:
    """Shape ids (train split, with rendered datapoints) by role; disjoint apart from
    ``ceiling``, which is every train shape outside ``validation``."""

    base: dict[int, tuple[str, ...]]  # base size → its base shapes (nested: smaller sets lie in larger ones)
    validation: tuple[str, ...]
    real_pool: tuple[str, ...]  # in a seeded order; ratio R of base size B takes the first round(R·B)
    ceiling: tuple[str, ...]
    test: tuple[str, ...] = ()  # the test split's rendered shapes (what a worker reads the test set by)


def experiment_split(train_ids: list[str], base: dict[int, list[str]], n_validation: int, seed: int) -> ExperimentSplit:
    """Draw the validation shapes (``n_validation``, seeded by ``seed`` alone) from the train
    shapes in no base set; the rest of those, shuffled, is the real pool."""
    in_base = set().union(*map(set, base.values())) if base else set()
    free = sorted(set(train_ids) - in_base)
    if n_validation > len(free):
        raise DataError(
            f"gqcnn.val_shapes = {n_validation}, but only {len(free)} train shapes lie outside the base sets"
        )
    order = [free[i] for i in shape_rng(seed, "gqcnn", "validation-and-real-pool").permutation(len(free))]
    validation = tuple(sorted(order[:n_validation]))
    ceiling = tuple(sorted(set(train_ids) - set(validation)))
    return ExperimentSplit(
        {b: tuple(sorted(ids)) for b, ids in base.items()}, validation, tuple(order[n_validation:]), ceiling
    )


def split_ids(split: ExperimentSplit) -> dict:
    """The shape ids of ``split`` by role as plain data (a seed's ``split.json``): ``validation``,
    ``real_pool`` (in its seeded order) and ``base`` (base size as text → its base shapes)."""
    return {
        "validation": split.validation,
        "real_pool": split.real_pool,
        "base": {str(b): ids for b, ids in split.base.items()},
    }


def with_split(index: pd.DataFrame, shapes: pd.DataFrame) -> pd.DataFrame:
    """The rendered original corpus's ``index`` with each datapoint's ``split`` from the shape table ``shapes``
    (``shape_id``, ``split``: the ``split`` stage's; the rendered index holds none, so one rendering serves every
    split)."""
    return index.assign(split=index.shape_id.map(shapes.set_index("shape_id")["split"]).to_numpy())


def load_split(
    original: Path, shapes: pd.DataFrame, base_sizes: list[int], n_validation: int, seed: int
) -> ExperimentSplit:
    """The split of the rendered original corpus (dataset folder ``original``) by the shape table ``shapes``
    and the base sets drawn from it (as ``generate`` draws them, so base sizes that are not
    augmented need no ``generate`` run)."""
    index = with_split(read_table(Path(original) / "index.parquet"), shapes)
    train_ids = sorted(index.shape_id[index.split == "train"].unique())
    rendered = set(train_ids)
    drawn = draw_base_sets(shapes, base_sizes, seed)
    base = {b: [s for s in ids if s in rendered] for b, ids in drawn.items()}
    test = tuple(sorted(index.shape_id[index.split == "test"].unique()))
    return dataclasses.replace(experiment_split(train_ids, base, n_validation, seed), test=test)


def _arrays(data: GraspImages, rows: np.ndarray) -> GraspArrays:
    return GraspArrays(data.images(rows), data.read("z", rows), data.read("labels", rows))


def _concat(parts: list[GraspArrays]) -> GraspArrays:
    return GraspArrays(*(np.concatenate([getattr(p, f) for p in parts]) for f in ("images", "z", "labels")))


def shapes_datapoints(original: Path, shape_ids: tuple[str, ...] | list[str]) -> tuple[GraspArrays, np.ndarray]:
    """The datapoints of ``shape_ids`` in the original corpus (dataset folder ``original``) and
    their rows in its index."""
    data = GraspImages.open(original)
    rows = np.flatnonzero(data.index.shape_id.isin(set(shape_ids)).to_numpy())
    return _arrays(data, rows), rows


def training_shapes(variant: Variant, split: ExperimentSplit) -> tuple[list[str], int]:
    """The original shapes a variant trains on and how many generated shapes it asks for."""
    if variant.pool == "ceiling":
        return list(split.ceiling), 0
    shapes, extra = list(split.base[variant.base_size]), ratio_count(variant.ratio, variant.base_size)
    if variant.pool == "real":
        if extra > len(split.real_pool):
            raise DataError(
                f"real pool at B = {variant.base_size}, 1:{variant.ratio:g} needs {extra} more train shapes; "
                f"{len(split.real_pool)} lie outside the base sets and validation (lower gqcnn.val_shapes "
                "or the ratio)"
            )
        return shapes + list(split.real_pool[:extra]), 0
    return shapes, extra


def targeted_added(base_size: int, ratio: float, corpora: Corpora) -> tuple[int, int]:
    """(datapoints, positives) that targeted at (``base_size``, ``ratio``) adds to its base set: those of the first
    round(R × B) targeted shapes in the corpus of base size B's generated shapes (labels read from its index)."""
    if base_size not in corpora.generated:
        raise DataError(f"targeted at B = {base_size} needs the rendered generated shapes of that base size")
    index = read_table(Path(corpora.generated[base_size]) / "index.parquet")
    rows = (index.pool == "targeted") & (index.order < ratio_count(ratio, base_size))
    return int(rows.sum()), int(index.label[rows].sum())


def targeted_share(variant: Variant, split: ExperimentSplit, corpora: Corpora) -> float:
    """The positive share of the training set of targeted at ``variant``'s (B, R): its base shapes' datapoints in
    the original corpus and those of :func:`targeted_added` (what a ``balanced`` network's batches are drawn at)."""
    data = GraspImages.open(corpora.original)
    base = data.index.shape_id.isin(set(split.base[variant.base_size])).to_numpy()
    n, positives = targeted_added(variant.base_size, variant.ratio, corpora)
    total = int(base.sum()) + n
    if not total:
        raise DataError(f"{variant.name}: targeted at its (B, R) has no datapoint to take a positive share of")
    return (int(data.read("labels", np.flatnonzero(base)).sum()) + positives) / total


def views_rows(variant: Variant, split: ExperimentSplit, corpora: Corpora) -> tuple[np.ndarray, int]:
    """The rows of the ``views`` corpus that a ``views`` network adds: as many datapoints as targeted at its (B, R)
    adds (:func:`targeted_added`), the first of the base shapes' extra-view datapoints in an order seeded by B alone
    (so a smaller ratio's rows are a prefix of a larger one's); and that count."""
    if corpora.views is None:
        raise DataError(f"{variant.name} needs the original shapes rendered from extra views (gqcnn.extra_views)")
    index = read_table(Path(corpora.views) / "index.parquet")
    wanted, _ = targeted_added(variant.base_size, variant.ratio, corpora)
    rows = np.flatnonzero(index.shape_id.isin(set(split.base[variant.base_size])).to_numpy())
    if wanted > len(rows):
        raise DataError(
            f"{variant.name} needs {wanted} extra-view datapoints of its base shapes (what targeted adds); the views "
            f"corpus holds {len(rows)} (raise gqcnn.extra_views)"
        )
    order = shape_rng(variant.base_size, "gqcnn", "views-order").permutation(len(rows))
    return np.sort(rows[order[:wanted]]), wanted


def training_set(variant: Variant, split: ExperimentSplit, corpora: Corpora) -> tuple[GraspArrays, dict]:
    """A variant's training datapoints, read from ``corpora``, and their counts (a ``balanced`` network's also
    ``target_positive_share``, the share its batches are drawn at; a ``views`` network's ``views_datapoints``)."""
    if variant.pool in SAMPLED_POOLS:
        base, rows = shapes_datapoints(corpora.original, split.base[variant.base_size])
        parts, extra = [base], {}
        if variant.pool == "balanced":
            extra = {"target_positive_share": round(targeted_share(variant, split, corpora), 6)}
        else:
            view_rows, wanted = views_rows(variant, split, corpora)
            if len(view_rows):
                parts.append(_arrays(GraspImages.open(corpora.views), view_rows))
            extra = {"original_datapoints": len(base), "views_datapoints": wanted}
        data = _concat(parts)
        info = {
            "original_shapes": len(split.base[variant.base_size]),
            "generated_shapes_asked": 0,
            "generated_shapes": 0,
            "datapoints": len(data),
            "positive_share": round(float(data.labels.mean()), 4) if len(data) else None,
        }
        return data, info | extra
    shapes, n_generated = training_shapes(variant, split)
    data, rows = shapes_datapoints(corpora.original, shapes)
    parts, generated_shapes = [data], 0
    if n_generated:
        if variant.base_size not in corpora.generated:
            raise DataError(
                f"{variant.name} needs the rendered generated shapes of base size {variant.base_size}; none were given"
            )
        generated = GraspImages.open(corpora.generated[variant.base_size])
        index = generated.index
        gen_rows = np.flatnonzero(((index.pool == variant.pool) & (index.order < n_generated)).to_numpy())
        if len(gen_rows):  # generated shapes may all lack datapoints (too wide for the hand)
            parts.append(_arrays(generated, gen_rows))
        generated_shapes = int(index.shape_id.iloc[gen_rows].nunique())
    data = _concat(parts)
    info = {
        "original_shapes": len(shapes),
        "generated_shapes_asked": n_generated,
        "generated_shapes": generated_shapes,
        "datapoints": len(data),
        "positive_share": round(float(data.labels.mean()), 4) if len(data) else None,
    }
    return data, info


def test_set(original: Path) -> tuple[GraspArrays, np.ndarray]:
    """Every test-split datapoint of the original corpus (dataset folder ``original``) by its index's own
    ``split`` column (a dataset that carries it, as `graspaug evaluate`'s test sets do) and its row in the index."""
    data = GraspImages.open(original)
    rows = np.flatnonzero((data.index.split == "test").to_numpy())
    return _arrays(data, rows), rows


def split_test_set(original: Path, split: ExperimentSplit) -> tuple[GraspArrays, np.ndarray]:
    """The test datapoints of ``split`` in the original corpus (dataset folder ``original``) and their rows in
    its index: its test shapes' (:func:`load_split`: the pipeline's rendered index holds no split), or, for a
    split that names none, the index's own (:func:`test_set`). The stage and its workers read them so."""
    return shapes_datapoints(original, split.test) if split.test else test_set(original)
