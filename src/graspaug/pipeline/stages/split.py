"""Stage ``split``: the objects table → the shape table, each shape in the ``train`` or ``test`` split.

A seeded shuffle of the objects (:func:`graspaug.augment.corpus.assign_split`; a duplicate goes where its original
goes). The seed is ``seed``, or with ``independent_draws`` on the pair (``seed``, ``data_seed``), so that every draw
of the data has its own test objects while ingest, the voxels and the originals' grasps and renders, which read the
objects table, are shared by every draw.

A split with fewer train or test shapes than the settings need (the largest of ``generate.base_sizes``,
``gqcnn.val_shapes``, the real pool that the real and recon networks, fidelity and the lifelong loop take, 2 test
shapes: :func:`graspaug.training.shape_counts.shape_count_problem`) stops the pipeline here, exit 2 with one line
naming the settings, before the AutoEncoder, the grasps and the renders run.

Outputs: ``data/shapes.parquet`` (the objects table with a ``split`` column).
"""

from __future__ import annotations

import logging

from graspaug.augment.corpus import split_objects, split_seed
from graspaug.io.tables import read_table, write_table
from graspaug.pipeline.params.base import params_model
from graspaug.pipeline.params.generate import GenerateParams
from graspaug.pipeline.params.gqcnn import GQCNNParams
from graspaug.pipeline.params.ingest import IngestParams
from graspaug.pipeline.params.lifelong import LifelongParams
from graspaug.pipeline.paths import OBJECTS_TABLE, SHAPES_TABLE
from graspaug.pipeline.shape_needs import params_shape_needs
from graspaug.pipeline.stages import StageError
from graspaug.training.shape_counts import shape_count_problem

log = logging.getLogger(__name__)

Params = params_model(
    "The params the `split` stage reads.",
    ingest=IngestParams,
    generate=GenerateParams,
    gqcnn=GQCNNParams,
    lifelong=LifelongParams,
)


def run(params: Params) -> None:
    seed = split_seed(params.seed, params.data_seed, params.independent_draws)
    shapes = split_objects(read_table(OBJECTS_TABLE), params.ingest.test_fraction, seed)
    counts = shapes["split"].value_counts()
    needs = params_shape_needs(params.generate, params.gqcnn, params.lifelong)
    n_train, n_test = int(counts.get("train", 0)), int(counts.get("test", 0))
    problem = shape_count_problem(n_train, n_test, needs, params.ingest.test_fraction)
    if problem:
        raise StageError(problem)
    write_table(shapes, SHAPES_TABLE)
    log.info(
        "split: %d shapes, %d train, %d test (seed %s)",
        len(shapes),
        counts.get("train", 0),
        counts.get("test", 0),
        seed,
    )


if __name__ == "__main__":
    from graspaug.pipeline.entry import stage_main

    stage_main(__spec__.name)
