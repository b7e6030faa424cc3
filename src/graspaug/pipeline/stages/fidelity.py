"""Stage ``fidelity``: how close each pool of one base size is to real shapes, before any network trains on it.

Per pool of ``gqcnn.pools`` at base size B (the shapes of the 1:1 augmentation set: the first B of each generated pool
and of the real pool, as the GQ-CNN experiment takes them), against B held-out real shapes (a seeded draw from the
test split): graspness and the share of the parents' graspness a child keeps, the share of positive rendered
datapoints, datapoints per shape and the share of the parents' a child keeps, median extents, and coverage / MMD /
1-NNA on the Chamfer distance (:func:`~graspaug.experiments.fidelity.numbers.fidelity_table`), each with a 95%
bootstrap interval over shapes.

Outputs: ``metrics/fidelity/<B>/<pool>_<figure>.json`` (``mean``, ``lo``, ``hi``: graspness kept, positive share,
datapoints per shape and kept, 1-NNA), ``reports/fidelity/<B>/{fidelity.csv,fidelity.md}``.
"""

from __future__ import annotations

import logging
import time

import numpy as np
import pandas as pd

from graspaug.augment.candidates import ratio_count
from graspaug.experiments.fidelity.numbers import (
    FIDELITY_POINTS,
    FIDELITY_RESAMPLES,
    fidelity_headline,
    fidelity_table,
    pool_shapes,
)
from graspaug.experiments.fidelity.words import fidelity_markdown
from graspaug.io.atomic import atomic_path
from graspaug.io.meshes import MESH_SUFFIX, mesh_path, read_mesh
from graspaug.io.tables import read_table, write_csv, write_json_files
from graspaug.pipeline.params.base import params_model
from graspaug.pipeline.params.generate import GenerateParams
from graspaug.pipeline.params.gqcnn import GQCNNParams
from graspaug.pipeline.paths import (
    GENERATED_SUFFIX,
    SCORES,
    SHAPES_DIR,
    SHAPES_TABLE,
    fidelity_metrics,
    fidelity_reports,
    generated_index,
    generated_meshes,
    gqcnn_dir,
    grasps_table,
)
from graspaug.pipeline.provenance import report_header
from graspaug.pipeline.stages import StageError
from graspaug.rng import shape_rng
from graspaug.training.gqcnn_data import load_split

log = logging.getLogger(__name__)

Params = params_model("The params the `fidelity` stage reads.", generate=GenerateParams, gqcnn=GQCNNParams)


def run(params: Params, base_size: int) -> None:
    gen, cfg, b = params.generate, params.gqcnn, base_size
    if b not in cfg.augment_base_sizes:
        raise StageError(f"base size {b} is not in gqcnn.augment_base_sizes {list(cfg.augment_base_sizes)}")
    start, count = time.perf_counter(), ratio_count(1.0, b)
    original, shapes = read_table(gqcnn_dir("original") / "index.parquet"), read_table(SHAPES_TABLE)
    rendered = pd.concat([original, read_table(gqcnn_dir(f"gen_{b}") / "index.parquet")])
    generated = read_table(generated_index(b)).sort_values("order")
    graspness = read_table(SCORES).set_index("shape_id").graspness.to_dict()
    graspness |= read_table(grasps_table(f"gen_{b}")).groupby("shape_id").success.mean().to_dict()
    pools, parent_counts = {}, original.groupby("shape_id").size().to_dict()  # a real shape's datapoints
    for pool in cfg.pools:
        if pool == "real":  # the real pool as the GQ-CNN experiment draws it
            split = load_split(gqcnn_dir("original"), shapes, list(gen.base_sizes), cfg.val_shapes, params.data_seed)
            ids, folder, suffix, parents = split.real_pool[:count], SHAPES_DIR, MESH_SUFFIX, None
        else:
            rows = generated[generated.pool == pool].head(count)
            parents = None if pool in ("primitives", "procedural") else rows  # no real parent
            ids, folder, suffix = list(rows.shape_id), generated_meshes(b), GENERATED_SUFFIX
        meshes = {s: read_mesh(mesh_path(folder, s, suffix)) for s in ids}
        rows = rendered[rendered.shape_id.isin(ids)]
        pools[pool] = pool_shapes(meshes, graspness, rows, FIDELITY_POINTS, params.seed, parents, parent_counts)
    test_ids = sorted(set(original.shape_id) & set(shapes.shape_id[shapes.split == "test"]))
    rng = shape_rng(params.seed, "fidelity", f"reference-{b}")
    reference_ids = [test_ids[i] for i in sorted(rng.choice(len(test_ids), size=min(b, len(test_ids)), replace=False))]
    reference_meshes = {s: read_mesh(mesh_path(SHAPES_DIR, s)) for s in reference_ids}
    reference = pool_shapes(reference_meshes, graspness, original.iloc[:0], FIDELITY_POINTS, params.seed).clouds
    table = fidelity_table(pools, reference, FIDELITY_RESAMPLES, np.random.default_rng([params.seed, b]))
    folder = fidelity_reports(b)
    folder.mkdir(parents=True, exist_ok=True)
    write_csv(table, folder / "fidelity.csv")
    with atomic_path(folder / "fidelity.md") as tmp:
        header = report_header(params.file_text, read_table(SHAPES_TABLE))  # the profile and corpus
        tmp.write_text(header + fidelity_markdown(table, b, len(reference)))
    write_json_files(fidelity_headline(table), fidelity_metrics(b))
    log.info(
        "fidelity %d: %d pools, %d real shapes, %.1f s", b, len(pools), len(reference), time.perf_counter() - start
    )


if __name__ == "__main__":
    import typer

    from graspaug.pipeline.entry import stage_main

    stage_main(__spec__.name, base_size=(int, typer.Option(..., "--base-size", "-b", help="The base set size B.")))
