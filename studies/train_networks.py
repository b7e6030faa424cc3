"""Train some of a profile's GQ-CNNs, exactly as ``train_gqcnn`` trains them, without the rest of the seed.

``train_gqcnn@<seed>`` trains every network of a seed (the study profile: 40 and more, about 30 min
per seed on 2 cores). Each network depends only on its variant, the seed's split, initial weights
and noise stream, so a subset trained here is the same as those networks of a full run. Reads the
project's ``params.yaml`` (e.g. after ``graspaug profile study``) and needs the datapoints the
chosen networks train on (``dvc repro render@original`` and, for augmented networks,
``render_generated@<B>``). ``--match`` picks networks by folder name (shell patterns,
``targeted/50-*``); they are written to ``<--out>/s<seed>/`` with the seed's ``test_rows.npy``,
``val_rows.npy`` and ``split.json``, as ``models/gqcnn/s<seed>/`` holds them. Prints one line per
network.

    python studies/train_networks.py --out study_models --match 'targeted/50-*' 'real/50-*' 'targeted/100-0'
"""

from __future__ import annotations

import argparse
import fnmatch
import time
from pathlib import Path

from graspaug.io.tables import read_table
from graspaug.pipeline.params.model import load_params
from graspaug.pipeline.paths import SHAPES_TABLE, gqcnn_dir
from graspaug.training.gqcnn_data import Corpora, load_split, shapes_datapoints, test_set
from graspaug.training.networks import NetworkJob, save_seed_split, seed_card, seed_members, train_network
from graspaug.training.variants import seed_variants


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, required=True, help="write s<seed>/<network>/ here")
    parser.add_argument("--match", nargs="+", required=True, help="network folder names, shell patterns")
    parser.add_argument("--seeds", type=int, nargs="+", default=None, help="default: gqcnn.seeds")
    args = parser.parse_args()
    params = load_params()
    cfg, gen = params.gqcnn, params.generate
    variants = [
        v
        for v in seed_variants(gen.base_sizes, gen.ratios, cfg.augment_base_sizes, cfg.ceiling, cfg.pools)
        if any(fnmatch.fnmatch(v.name, pattern) for pattern in args.match)
    ]
    if not variants:
        raise SystemExit(f"no network of this profile matches {args.match}")
    augmented = sorted({v.base_size for v in variants if v.ratio > 0})
    corpora = Corpora(gqcnn_dir("original"), {b: gqcnn_dir(f"gen_{b}") for b in augmented})
    split = load_split(
        corpora.original, read_table(SHAPES_TABLE), list(gen.base_sizes), cfg.val_shapes, params.data_seed
    )
    val, val_rows = shapes_datapoints(corpora.original, split.validation)
    test, test_rows = test_set(corpora.original)
    card = seed_card(params.render, params.grasps, params.seed)
    for seed in args.seeds if args.seeds is not None else cfg.seeds:
        folder = args.out / f"s{seed}"
        folder.mkdir(parents=True, exist_ok=True)
        inits, noise_seeds = seed_members(cfg.net, params.seed, seed, cfg.members)
        for v in variants:
            start = time.perf_counter()
            job = NetworkJob(v, split, cfg.net, cfg.train, inits, noise_seeds, seed, "cpu", folder, corpora, card)
            result = train_network(job, val, test)
            ap = {k: round(result[k]["ap"], 4) for k in ("validation", "test")}
            print(f"s{seed} {v.name}: AP {ap}, {time.perf_counter() - start:.0f} s", flush=True)
        save_seed_split(folder, split, test_rows, val_rows)


if __name__ == "__main__":
    main()
