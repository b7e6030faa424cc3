"""Stage ``train_gqcnn``: every GQ-CNN of one training seed, as a paired set.

Networks (``graspaug.experiments.networks.seed_variants``): targeted at every base size ×
ratio of ``generate``; random and real at every nonzero ratio of ``gqcnn.augment_base_sizes``;
the ceiling. All start from the seed's initial weights and noise stream and are validated on
the same ``gqcnn.val_shapes`` train shapes (``graspaug.training.gqcnn_data``); each keeps the
weights of its best validation AP. With ``gqcnn.members`` > 1 each network is an ensemble of
that many members, member m starting from the same weights in every variant. Networks train one
after another with every thread. Test set: every test-split datapoint of ``data/gqcnn/original``.

Outputs: ``models/gqcnn/s<seed>/`` (one folder per network, ``test_rows.npy``,
``val_rows.npy``, ``split.json``), ``metrics/gqcnn/s<seed>.json`` (validation and test AP per
network), ``reports/gqcnn/validation/s<seed>.{png,csv}`` (validation AP vs step of every
network) and ``reports/timing/train_gqcnn/s<seed>.json``.
"""

from __future__ import annotations

import json
import logging
import time

import numpy as np
import torch
from tqdm import tqdm

from graspaug.device import has_native_bfloat16, resolve_device
from graspaug.experiments.networks import (
    NetworkJob,
    read_history,
    seed_members,
    seed_table,
    seed_variants,
    train_network,
)
from graspaug.io.atomic import atomic_path
from graspaug.io.checkpoints import gqcnn_card
from graspaug.io.tables import read_table, write_csv, write_json
from graspaug.params.base import params_model
from graspaug.params.generate import GenerateParams
from graspaug.params.gqcnn import GQCNNParams
from graspaug.params.grasps import GraspsParams
from graspaug.params.render import RenderParams
from graspaug.paths import SHAPES_TABLE, gqcnn_dir, gqcnn_seed_dir, gqcnn_seed_metrics, gqcnn_val_curves, timing_file
from graspaug.stages import StageError
from graspaug.training.gqcnn_data import Corpora, load_split, shapes_datapoints, test_set

log = logging.getLogger(__name__)

Params = params_model(
    "The params the `train_gqcnn` stage reads.",
    grasps=GraspsParams,
    generate=GenerateParams,
    render=RenderParams,
    gqcnn=GQCNNParams,
)


def run(params: Params, seed: int) -> None:
    from graspaug.plots import validation_curves

    cfg, gen = params.gqcnn, params.generate
    if seed not in cfg.seeds:
        raise StageError(f"seed {seed} is not in gqcnn.seeds {list(cfg.seeds)}")
    start = time.perf_counter()
    corpora = Corpora(gqcnn_dir("original"), {b: gqcnn_dir(f"gen_{b}") for b in cfg.augment_base_sizes})
    # too few shapes for the validation set: a DataError, which the CLI prints in one line
    split = load_split(corpora.original, read_table(SHAPES_TABLE), list(gen.base_sizes), cfg.val_shapes, params.seed)
    variants = seed_variants(gen.base_sizes, gen.ratios, cfg.augment_base_sizes, cfg.ceiling)
    device = resolve_device(params.device)
    inits, noise_seeds = seed_members(cfg.net, params.seed, seed, cfg.members)
    val, val_rows = shapes_datapoints(corpora.original, split.validation)
    test, test_rows = test_set(corpora.original)
    log.info(
        "train_gqcnn seed %d: %d networks of %d member(s); validation %d shapes (%d datapoints), test %d "
        "datapoints; one at a time on %s",
        seed,
        len(variants),
        cfg.members,
        len(split.validation),
        len(val_rows),
        len(test_rows),
        device,
    )
    if cfg.train.precision == "bfloat16" and not has_native_bfloat16(device):
        log.warning(
            "gqcnn.train.precision: bfloat16, but this %s has no bfloat16 instructions: training is emulated "
            "and slower than float32 (-S gqcnn.train.precision=float32)",
            device.type.upper(),
        )
    # one network at a time with every thread: two 1-thread workers were slower on 2 cores
    # (docs/results.md#benchmarks)
    with atomic_path(gqcnn_seed_dir(seed), directory=True) as folder:
        card = gqcnn_card(
            params.render.crop,
            params.render.intrinsics,
            params.render.viewpoints,
            params.grasps.gripper,
            params.grasps.threshold,
            params.seed,
        )
        results = []
        for variant in tqdm(variants, desc=f"train GQ-CNNs (seed {seed})", unit="network"):
            job = NetworkJob(
                variant, split, cfg.net, cfg.train, inits, noise_seeds, seed, str(device), folder, corpora, card
            )
            try:
                results.append(train_network(job, val, test))
            except ValueError as exc:
                raise StageError(str(exc)) from None
        np.save(folder / "test_rows.npy", test_rows)
        np.save(folder / "val_rows.npy", val_rows)
        split_ids = {
            "validation": split.validation,
            "real_pool": split.real_pool,
            "base": {str(b): ids for b, ids in split.base.items()},
        }
        (folder / "split.json").write_text(json.dumps(split_ids, indent=1) + "\n")
        history = read_history(folder, variants)
    write_csv(history, gqcnn_val_curves(seed).with_suffix(".csv"))
    validation_curves(
        history, gqcnn_val_curves(seed), f"Validation AP of every network of seed {seed} (dots: the kept weights)"
    )
    write_json({"seed": seed, "networks": seed_table(results)}, gqcnn_seed_metrics(seed))
    speed = [r["samples_per_second"] for r in results]
    write_json(
        {
            "seconds": round(time.perf_counter() - start, 1),
            "networks": len(results),
            "threads": torch.get_num_threads(),
            "samples_per_second_median": round(float(np.median(speed)), 1),
            "train_seconds": {
                f"{r['pool']}/{r['base_size']}-{r['ratio']:g}": round(r["train_seconds"], 1) for r in results
            },
        },
        timing_file("train_gqcnn", f"s{seed}"),
    )
    for r in sorted(results, key=lambda r: (r["pool"], r["base_size"], r["ratio"])):
        log.info(
            "train_gqcnn seed %d %s %d-%g: %d datapoints, %d steps (kept %s); validation AP %.4f, test AP %.4f",
            seed,
            r["pool"],
            r["base_size"],
            r["ratio"],
            r["train"]["datapoints"],
            r["train"]["steps"],
            r["train"]["best_step"],
            r["validation"]["ap"] or float("nan"),
            r["test"]["ap"] or float("nan"),
        )
    log.info("train_gqcnn seed %d: %d networks in %.1f s", seed, len(results), time.perf_counter() - start)
