"""One GQ-CNN's training time at 1 and at 2 torch threads: what a cluster task's one thread
(``graspaug.training.networks.TASK_THREADS``) costs or saves against a network that has the cores to
itself, on the project's params and rendered datapoints.

Trains one network of seed 0 (``--network``, a folder name as ``train_gqcnn`` writes it) exactly as
``train_gqcnn`` does (:func:`graspaug.training.networks.train_network`), ``--rounds`` times at each thread
count, the counts taking turns (each round starts with another), so a machine that speeds up or slows down
shifts both; prints the median training seconds and samples per second of each and their ratio. Needs
``data/gqcnn/original`` (``dvc repro render@original``) and ``params.yaml`` (e.g. ``graspaug profile tiny``).

    python bench/gqcnn_task_threads.py [--network targeted/6-0] [--rounds 5]
"""

from __future__ import annotations

import argparse
import json
import tempfile
from pathlib import Path

import numpy as np
import torch

from graspaug.io.tables import read_table
from graspaug.pipeline.params.model import load_params
from graspaug.pipeline.paths import SHAPES_TABLE, gqcnn_dir
from graspaug.training.gqcnn_data import Corpora, load_split, shapes_datapoints, test_set
from graspaug.training.networks import NetworkJob, seed_card, seed_members, train_network
from graspaug.training.variants import seed_variants


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--network", default=None, help="default: the seed's first network")
    parser.add_argument("--rounds", type=int, default=5)
    args = parser.parse_args()
    params = load_params()
    cfg, gen = params.gqcnn, params.generate
    variants = seed_variants(gen.base_sizes, gen.ratios, cfg.augment_base_sizes, cfg.ceiling, cfg.pools)
    variant = next(v for v in variants if args.network in (None, v.name))
    corpora = Corpora(gqcnn_dir("original"), {b: gqcnn_dir(f"gen_{b}") for b in cfg.augment_base_sizes})
    split = load_split(corpora.original, read_table(SHAPES_TABLE), list(gen.base_sizes), cfg.val_shapes, 0)
    val, test = shapes_datapoints(corpora.original, split.validation)[0], test_set(corpora.original)[0]
    inits, noise_seeds = seed_members(cfg.net, params.seed, 0, cfg.members)
    card = seed_card(params.render, params.grasps, params.seed)
    seconds: dict[int, list[float]] = {1: [], 2: []}
    speed: dict[int, list[float]] = {1: [], 2: []}
    with tempfile.TemporaryDirectory() as out:
        job = NetworkJob(variant, split, cfg.net, cfg.train, inits, noise_seeds, 0, "cpu", Path(out), corpora, card)
        for r in range(args.rounds):
            for threads in (1, 2) if r % 2 == 0 else (2, 1):
                torch.set_num_threads(threads)
                result = train_network(job, val, test)
                seconds[threads].append(result["train_seconds"])
                speed[threads].append(result["samples_per_second"])
    median = {t: (float(np.median(seconds[t])), float(np.median(speed[t]))) for t in seconds}
    print(
        json.dumps(
            {
                "network": variant.name,
                "steps": result["train"]["steps"],
                "batch_size": cfg.train.batch_size,
                "members": cfg.members,
                "rounds": args.rounds,
                **{
                    f"threads_{t}": {"train_seconds": round(s, 3), "samples_per_second": round(v)}
                    for t, (s, v) in median.items()
                },
                "speedup_2_over_1": round(median[1][0] / median[2][0], 2),
            },
            indent=1,
        )
    )


if __name__ == "__main__":
    main()
