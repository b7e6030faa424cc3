"""How many members per GQ-CNN (``gqcnn.members``) make the paired contrasts tight: the
seed-to-seed SD of every declared contrast for ensembles of 1 … K members.

Members 0 … M−1 are the ``gqcnn.members`` = M members ``train_gqcnn`` already trained into
``models/gqcnn/s<seed>/`` (the same initial weights and noise streams, checked by their
``init_digest``); this trains members M … K−1 of every network of every seed in ``params.yaml``
into ``studies/out/members/s<seed>/m<m>/`` (resumable: a member already there is read, not
retrained). Then for k = 1 … K the network is
the ensemble of members 0 … k−1 (mean P(success)), and per k it prints each declared contrast
of :mod:`graspaug.experiments.ap` (the ratio chosen on the ensembles' mean validation AP):
mean over seeds, 95% t-interval, SD over seeds; and each network's test AP, the ensemble's
against its members' mean. Run where ``dvc repro train_gqcnn`` has run with these params:

    python studies/gqcnn_members.py [--members 4] [--out studies/out/members]

Members M … K−1 cost about (K−M) / M times ``train_gqcnn``'s time (the stage trains a network's
members at once, this study its extra members at once, one network at a time, every thread).
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np
import pandas as pd
from sklearn.metrics import average_precision_score

from graspaug.experiments.ap.numbers import choose_ratios, declared_contrasts
from graspaug.experiments.stats import t_interval
from graspaug.io.tables import read_table
from graspaug.pipeline.params.model import load_params
from graspaug.pipeline.paths import SHAPES_TABLE, gqcnn_dir, gqcnn_seed_dir
from graspaug.training.gqcnn_data import Corpora, load_split, shapes_datapoints, test_set
from graspaug.training.networks import (
    NetworkJob,
    initial_weights,
    members_digest,
    network_dir,
    seed_members,
    stream_seeds,
    train_network,
)
from graspaug.training.variants import seed_variants


def train_extra_members(params, split, variants, val, test, members: int, out: Path, corpora: Corpora) -> None:
    """Members ``gqcnn.members`` … ``members``−1 of every network (``variants``) of every seed, one
    at a time (skipping those on disk); ``val`` / ``test``: the experiment's datapoints, read from ``corpora``."""
    cfg = params.gqcnn
    for seed in cfg.seeds:
        expected = members_digest(seed_members(cfg.net, params.seed, seed, cfg.members)[0])
        for v in variants:  # members 0 … M−1 must be the pipeline's
            saved = json.loads((network_dir(gqcnn_seed_dir(seed), v) / "summary.json").read_text())["init_digest"]
            if saved != expected:
                raise SystemExit(
                    f"models/gqcnn/s{seed}/{v.name} was not trained with these params' members: rerun `dvc repro "
                    "train_gqcnn`"
                )
        for m in range(cfg.members, members):
            weight_seed, noise_seed = stream_seeds(params.seed, seed, m)
            init, folder = initial_weights(cfg.net, weight_seed), out / f"s{seed}" / f"m{m}"
            for v in variants:
                if (network_dir(folder, v) / "summary.json").exists():
                    continue
                job = NetworkJob(v, split, cfg.net, cfg.train, (init,), (noise_seed,), seed, "cpu", folder, corpora)
                r = train_network(job, val, test)
                print(
                    f"  s{seed} m{m} {v.name}: validation AP {r['validation']['ap']:.4f}, test AP "
                    f"{r['test']['ap']:.4f} "
                    f"({r['train_seconds']:.0f} s)",
                    flush=True,
                )


def member_predictions(seed: int, m: int, v, kind: str, out: Path, pipeline_members: int) -> np.ndarray:
    """Member m's P(success) on the validation or test datapoints (``kind``: val, test)."""
    if m >= pipeline_members:
        return np.load(network_dir(out / f"s{seed}" / f"m{m}", v) / f"{kind}_predictions.npy")
    folder = network_dir(gqcnn_seed_dir(seed), v)
    return (
        np.load(folder / f"{kind}_predictions.npy")
        if pipeline_members == 1
        else np.load(folder / f"{kind}_predictions_members.npy")[m]
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--members", type=int, default=4, help="Largest ensemble K.")
    parser.add_argument("--out", type=Path, default=Path("studies/out/members"))
    args = parser.parse_args()
    params = load_params("params.yaml")
    cfg, gen = params.gqcnn, params.generate
    if args.members < cfg.members:
        parser.error(f"--members {args.members} is below gqcnn.members ({cfg.members}) of params.yaml")
    corpora = Corpora(gqcnn_dir("original"), {b: gqcnn_dir(f"gen_{b}") for b in cfg.augment_base_sizes})
    split = load_split(
        corpora.original, read_table(SHAPES_TABLE), list(gen.base_sizes), cfg.val_shapes, params.data_seed
    )
    variants = seed_variants(gen.base_sizes, gen.ratios, cfg.augment_base_sizes, cfg.ceiling, cfg.pools)
    val, test = shapes_datapoints(corpora.original, split.validation)[0], test_set(corpora.original)[0]  # read once
    train_extra_members(params, split, variants, val, test, args.members, args.out, corpora)
    val_labels, test_labels = val.labels, test.labels
    rows = []
    for seed in cfg.seeds:
        for v in variants:
            val_p = [member_predictions(seed, m, v, "val", args.out, cfg.members) for m in range(args.members)]
            test_p = [member_predictions(seed, m, v, "test", args.out, cfg.members) for m in range(args.members)]
            for k in range(1, args.members + 1):
                rows.append(
                    {
                        "pool": v.pool,
                        "base_size": v.base_size,
                        "ratio": float(v.ratio),
                        "seed": seed,
                        "members": k,
                        "val_ap": average_precision_score(val_labels, np.mean(val_p[:k], axis=0)),
                        "test_ap": average_precision_score(test_labels, np.mean(test_p[:k], axis=0)),
                        "member_test_ap": average_precision_score(test_labels, test_p[k - 1]),
                    }
                )
    table = pd.DataFrame(rows)
    args.out.mkdir(parents=True, exist_ok=True)
    table.to_csv(args.out / "ap_by_members.csv", index=False)
    fmt = lambda t: f"{t['mean']:+.4f} [{t['low']:+.4f}, {t['high']:+.4f}]"  # noqa: E731
    print(f"\n{len(cfg.seeds)} seeds; contrast: mean [95% t over seeds], SD over seeds, for ensembles of k members")
    for k in range(1, args.members + 1):
        runs = table[table.members == k]
        chosen = choose_ratios(runs, cfg.augment_base_sizes)
        ap = runs.set_index(["pool", "base_size", "ratio", "seed"]).test_ap
        for c in declared_contrasts(gen.base_sizes, gen.ratios, cfg.augment_base_sizes, chosen, cfg.pools):
            per_seed = [sum(w * ap[(*key, s)] for w, key in c.terms) for s in cfg.seeds]
            print(f"k = {k}  {c.name:30s} {fmt(t_interval(per_seed)):32s} SD {np.std(per_seed, ddof=1):.4f}")
    print("\nnetwork test AP by k: ensemble mean over seeds (SD over seeds); the k-th member alone (mean over seeds)")
    for (pool, base, ratio), g in table.groupby(["pool", "base_size", "ratio"], sort=False):
        cells = [
            f"k={k}: {g[g.members == k].test_ap.mean():.4f} ({g[g.members == k].test_ap.std():.4f})"
            for k in range(1, args.members + 1)
        ]
        print(
            f"{pool:9s} {base:4d}-{ratio:g}  " + "  ".join(cells) + f"  | members alone {g.member_test_ap.mean():.4f}"
        )


if __name__ == "__main__":
    main()
