"""Which GQ-CNN options validate best: width and input, chosen on validation AP, never on test.

Trains the experiment's 1:0 networks (base sets of ``--base-sizes``) under each option, in
paired seeds (every option of a seed starts from the same noise stream; initial weights are
drawn per option from the seed, since the shapes differ), and prints validation AP per option:
mean over seeds, 95% t-interval, and the paired difference to the default with its interval,
plus training samples/s. Run it in a project where ``render@original`` has run with the
default params (it reads ``data/shapes.parquet`` and ``data/gqcnn/original``):

    python studies/gqcnn_options.py [--seeds 0 1 2] [--base-sizes 50 200] [--options NAME ...]

The training budget is the params' (``gqcnn.train``): set it in params.yaml first.
"""

from __future__ import annotations

import argparse
import dataclasses
import time

import numpy as np
import torch

from graspaug.experiments.stats import t_interval
from graspaug.io.tables import read_table
from graspaug.nets.gqcnn import GQCNN
from graspaug.pipeline.params.model import Params
from graspaug.pipeline.paths import SHAPES_TABLE, gqcnn_dir
from graspaug.training.gqcnn import classification_metrics, predict, train_gqcnn
from graspaug.training.gqcnn_data import Corpora, load_split, shapes_datapoints, training_set
from graspaug.training.networks import initial_weights, stream_seeds
from graspaug.training.variants import Variant

OPTIONS = {  # name → (changes to gqcnn.net, changes to gqcnn.train); the first is the params' own
    "params as they are": ({}, {}),
    "lr 0.05": ({}, {"lr": 0.05}),
    "lr 0.01": ({}, {"lr": 0.01}),
    "FC 256": ({"fc": 256}, {}),
    "16 filters": ({"filters": 16}, {}),
    "depth minus gripper": ({"image_input": "depth_minus_gripper"}, {}),
    "depth": ({"image_input": "depth"}, {}),
    "EMA 0.99": ({}, {"ema_decay": 0.99}),
    "EMA 0.98": ({}, {"ema_decay": 0.98}),
    "min_steps 500": ({}, {"min_steps": 500}),
    "EMA 0.99, min_steps 500": ({}, {"ema_decay": 0.99, "min_steps": 500}),
    "EMA 0.99, 10 evaluations": ({}, {"ema_decay": 0.99, "evals": 10}),
    "min_steps 800": ({}, {"min_steps": 800}),
    "16 passes": ({}, {"epochs": 16.0}),
    "EMA off": ({}, {"ema_decay": 0.0}),
    "bfloat16": ({}, {"precision": "bfloat16"}),
    "float32": ({}, {"precision": "float32"}),
}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seeds", type=int, nargs="+", default=[0, 1, 2])
    parser.add_argument("--base-sizes", type=int, nargs="+", default=[50, 200])
    parser.add_argument("--threads", type=int, default=torch.get_num_threads())
    parser.add_argument(
        "--options", nargs="+", default=list(OPTIONS), help="Which options, by name (the first is the reference)."
    )
    args = parser.parse_args()
    torch.set_num_threads(args.threads)
    params = Params()
    cfg = params.gqcnn
    corpora = Corpora(gqcnn_dir("original"))
    split = load_split(
        corpora.original, read_table(SHAPES_TABLE), list(params.generate.base_sizes), cfg.val_shapes, params.data_seed
    )
    val, _ = shapes_datapoints(corpora.original, split.validation)
    sets = {b: training_set(Variant("targeted", b, 0.0), split, corpora)[0] for b in args.base_sizes}
    print(
        f"validation: {len(split.validation)} shapes, {len(val)} datapoints; training sets: "
        + ", ".join(f"B = {b}: {len(d)}" for b, d in sets.items())
        + f"; seeds {args.seeds}; {args.threads} threads"
    )
    val_ap: dict = {}
    speed: dict = {}
    options = {name: OPTIONS[name] for name in args.options}
    for name, (net_change, train_change) in options.items():
        net_cfg, train_cfg = dataclasses.replace(cfg.net, **net_change), dataclasses.replace(cfg.train, **train_change)
        for seed in args.seeds:
            weight_seed, noise_seed = stream_seeds(params.seed, seed)
            init = initial_weights(net_cfg, weight_seed)
            for b, train in sets.items():
                net = GQCNN(net_cfg)
                net.load_state_dict(init)
                start = time.perf_counter()
                fit = train_gqcnn(
                    net,
                    train,
                    val,
                    train_cfg,
                    torch.device("cpu"),
                    torch.Generator().manual_seed(noise_seed),
                    progress=False,
                )
                speed.setdefault(name, []).append(fit["steps"] * train_cfg.batch_size / (time.perf_counter() - start))
                val_ap[name, b, seed] = classification_metrics(
                    val.labels, predict(net, val, torch.device("cpu"), cfg.train.eval_batch)
                )["ap"]
                print(
                    f"  {name:38s} B = {b:4d} seed {seed}: validation AP {val_ap[name, b, seed]:.4f} ({fit['steps']} "
                    f"steps, kept {fit['best_step']})",
                    flush=True,
                )
    default = next(iter(options))

    def fmt(t):
        return f"{t['mean']:+.4f} [{t['low']:+.4f}, {t['high']:+.4f}]" if t["low"] is not None else f"{t['mean']:+.4f}"  # noqa: E731

    print(
        "\noption                                 B     validation AP (95% t)          vs default (paired, 95% t)    "
        "  samples/s"
    )
    for name in options:
        for b in args.base_sizes:
            own = t_interval([val_ap[name, b, s] for s in args.seeds])
            diff = t_interval([val_ap[name, b, s] - val_ap[default, b, s] for s in args.seeds])
            print(
                f"{name:38s} {b:4d}  {fmt(own):30s} {fmt(diff) if name != default else '':30s} "
                f"{np.median(speed[name]):8.0f}"
            )
    if len(args.base_sizes) > 1:  # the positive control on validation: largest minus smallest base set, per seed
        small, large = min(args.base_sizes), max(args.base_sizes)
        print(
            f"\noption                                 validation AP(B = {large}) - AP(B = {small}): mean [95% t], SD "
            "over seeds"
        )
        for name in options:
            gains = [val_ap[name, large, s] - val_ap[name, small, s] for s in args.seeds]
            print(
                f"{name:38s} {fmt(t_interval(gains)):30s} SD "
                f"{np.std(gains, ddof=1) if len(gains) > 1 else float('nan'):.4f}  "
                f"SD of AP(B = {small}) "
                f"{np.std([val_ap[name, small, s] for s in args.seeds], ddof=1) if len(args.seeds) > 1 else np.nan:.4f}"
            )


if __name__ == "__main__":
    main()
