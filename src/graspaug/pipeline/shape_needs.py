"""The shapes the params need of the corpus (:class:`~graspaug.training.shape_counts.ShapeNeeds`), from the sections
that decide them, for the stages that count shapes: ``split`` (the shapes ingest kept) and ``generate`` (the train
shapes render@original could picture, which its recon pool's real pool is drawn from)."""

from __future__ import annotations

import dataclasses
from typing import TYPE_CHECKING

import numpy as np

from graspaug.augment.settings import GenerateSettings
from graspaug.errors import DataError
from graspaug.pipeline.params.gqcnn import GQCNNParams
from graspaug.pipeline.params.ingest import IngestParams
from graspaug.pipeline.params.lifelong import LifelongParams
from graspaug.training.shape_counts import ShapeNeeds, shape_count_problem, shape_needs
from graspaug.training.variants import seed_networks

if TYPE_CHECKING:
    from graspaug.training.gqcnn_data import ExperimentSplit

RENDERED = "with datapoints from render@original"  # it skips a shape none of whose grasps it can picture


def params_shape_needs(
    generate: GenerateSettings, gqcnn: GQCNNParams, lifelong: LifelongParams | None = None
) -> ShapeNeeds:
    """What ``generate``, ``gqcnn`` and (where given) ``lifelong`` need of the train and test splits: the largest base
    set, the validation shapes, the real pool that a training seed's networks (:func:`seed_networks`), the fidelity
    stage and the lifelong loop's real arm take, and the test shapes."""
    sizes = (generate.base_sizes, generate.ratios, gqcnn.augment_base_sizes, gqcnn.ceiling, gqcnn.pools)
    variants = seed_networks(gqcnn.networks, *sizes, gqcnn.control_ratios)
    added = len(lifelong.rounds) * lifelong.shapes_per_round if lifelong is not None else 0
    return shape_needs(generate.base_sizes, gqcnn.val_shapes, variants, gqcnn.pools, gqcnn.augment_base_sizes, added)


def real_pool_ids(
    split: ExperimentSplit, ingest: IngestParams, generate: GenerateSettings, gqcnn: GQCNNParams
) -> np.ndarray:
    """The real pool's shape ids of ``split`` (:func:`~graspaug.training.gqcnn_data.load_split` of the rendered
    original corpus), or a :class:`DataError` in one line (:func:`shape_count_problem`) where render@original left
    fewer train or test shapes than the settings need (the split stage checked the shapes ingest kept; render skips a
    shape none of whose grasps it can picture)."""
    rendered = len(split.ceiling) + len(split.validation), len(split.test)
    needs = params_shape_needs(generate, gqcnn)  # the base sets as rendered: load_split drops unrendered base shapes
    needs = dataclasses.replace(needs, base=max((len(ids) for ids in split.base.values()), default=0))
    problem = shape_count_problem(*rendered, needs, ingest.test_fraction, RENDERED)
    if problem:
        raise DataError(problem)
    return np.array(split.real_pool)
