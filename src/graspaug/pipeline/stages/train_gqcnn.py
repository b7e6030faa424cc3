"""Stage ``train_gqcnn``: every GQ-CNN of one training seed, as a paired set.

Networks (``training.variants.seed_networks``): ``generate`` × ``gqcnn.pools``, or ``gqcnn.networks``; the ceiling. All
start from the seed's initial weights and noise stream, are validated on the same ``gqcnn.val_shapes`` train shapes
and keep the weights of their best validation AP (``gqcnn.members`` > 1: ensembles); tested on the corpus's test set.

Outputs: ``models/gqcnn/s<seed>/`` (one folder per network, ``test_rows.npy``, ``val_rows.npy``, ``split.json``),
``metrics/gqcnn/s<seed>.json`` (test and validation AP, means over the networks), ``reports/gqcnn/networks/
s<seed>.json`` (AP per network), ``reports/gqcnn/validation/s<seed>.{png,csv}`` (validation AP vs step).
"""

from __future__ import annotations

import logging
import time

from graspaug.device import GQCNN_GPU_BFLOAT16, log_precision, resolve_device
from graspaug.io.atomic import atomic_path
from graspaug.io.tables import read_table, write_csv, write_json
from graspaug.pipeline.params.base import params_model
from graspaug.pipeline.params.generate import GenerateParams
from graspaug.pipeline.params.gqcnn import GQCNNParams
from graspaug.pipeline.params.grasps import GraspsParams
from graspaug.pipeline.params.ingest import IngestParams
from graspaug.pipeline.params.render import RenderParams
from graspaug.pipeline.paths import (
    SHAPES_TABLE,
    gqcnn_dir,
    gqcnn_seed_dir,
    gqcnn_seed_metrics,
    gqcnn_seed_networks,
    gqcnn_val_curves,
    timing_file,
)
from graspaug.pipeline.stages import StageError
from graspaug.plots import validation_curves
from graspaug.training.gqcnn_data import Corpora, load_split, shapes_datapoints, split_test_set
from graspaug.training.networks import (
    NetworkJob,
    network_seed,
    network_workers,
    read_history,
    result_lines,
    save_seed_split,
    seed_card,
    seed_headline,
    seed_members,
    seed_plan,
    seed_table,
    seed_timing,
    train_jobs,
)
from graspaug.training.variants import seed_networks

log = logging.getLogger(__name__)

Params = params_model(
    "The params the `train_gqcnn` stage reads.",
    ingest=IngestParams,
    grasps=GraspsParams,
    generate=GenerateParams,
    render=RenderParams,
    gqcnn=GQCNNParams,
)


def run(params: Params, seed: int) -> None:
    cfg, gen, start = params.gqcnn, params.generate, time.perf_counter()
    if seed not in cfg.seeds:
        raise StageError(f"seed {seed} is not in gqcnn.seeds {list(cfg.seeds)}")
    generated = {b: gqcnn_dir(f"gen_{b}") for b in cfg.augment_base_sizes}  # views: render_views, empty at 0 views
    corpora = Corpora(gqcnn_dir("original"), generated, gqcnn_dir("views"))
    shapes = read_table(SHAPES_TABLE)  # too few for the validation set: a DataError, printed in one line
    split = load_split(corpora.original, shapes, list(gen.base_sizes), cfg.val_shapes, params.data_seed)
    sizes = (gen.base_sizes, gen.ratios, cfg.augment_base_sizes, cfg.ceiling, cfg.pools, cfg.control_ratios)
    variants = seed_networks(cfg.networks, *sizes)
    device = resolve_device(params.device)
    global_seed = network_seed(params.seed, params.data_seed, params.independent_draws)
    inits, noise_seeds = seed_members(cfg.net, global_seed, seed, cfg.members)
    val, val_rows = shapes_datapoints(corpora.original, split.validation)
    test, test_rows = split_test_set(corpora.original, split)
    plan = seed_plan(variants, cfg.members, len(split.validation), val_rows, test_rows, device)
    log.info("train_gqcnn seed %d: %s", seed, plan)
    log_precision(f"train_gqcnn seed {seed}", "gqcnn.train.precision", cfg.train.precision, device, GQCNN_GPU_BFLOAT16)
    with atomic_path(gqcnn_seed_dir(seed), directory=True) as folder:
        card = seed_card(params.render, params.grasps, global_seed, params.ingest, params.data_seed, cfg.train)
        shared = (split, cfg.net, cfg.train, inits, noise_seeds, seed, str(device), folder, corpora, card)
        jobs = [NetworkJob(v, *shared) for v in variants]
        results = train_jobs(jobs, val, test, f"train GQ-CNNs (seed {seed})", network_workers(params.workers))
        save_seed_split(folder, split, test_rows, val_rows)
        history = read_history(folder, variants)
    write_csv(history, gqcnn_val_curves(seed).with_suffix(".csv"))
    title = f"Validation AP of every network of seed {seed} (dots: the kept weights)"
    validation_curves(history, gqcnn_val_curves(seed), title)
    write_json({"seed": seed, "networks": (table := seed_table(results))}, gqcnn_seed_networks(seed))
    write_json(seed_headline(table), gqcnn_seed_metrics(seed))
    write_json(seed_timing(results, time.perf_counter() - start), timing_file("train_gqcnn", f"s{seed}"))
    for line in result_lines(results):
        log.info("train_gqcnn seed %d %s", seed, line)
    log.info("train_gqcnn seed %d: %d networks in %.1f s", seed, len(results), time.perf_counter() - start)


if __name__ == "__main__":
    import typer

    from graspaug.pipeline.entry import stage_main

    stage_main(__spec__.name, seed=(int, typer.Option(0, "--seed", "-s", help="Training seed (one of gqcnn.seeds).")))
