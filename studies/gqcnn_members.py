"""How many members per GQ-CNN (``gqcnn.members``) make the paired contrasts tight: the
seed-to-seed SD of every declared contrast for ensembles of 1 … K members.

Trains members 1 … K−1 of every network of every seed in ``params.yaml`` (member 0 is the
network ``train_gqcnn`` already wrote to ``models/gqcnn/s<seed>/``: the same initial weights and
noise stream, checked by its ``init_digest``) into ``studies/out/members/s<seed>/m<m>/``
(resumable: a member already there is read, not retrained). Then for k = 1 … K the network is
the ensemble of members 0 … k−1 (mean P(success)), and per k it prints each declared contrast
of :mod:`graspaug.experiments.ap` (the ratio chosen on the ensembles' mean validation AP):
mean over seeds, 95% t-interval, SD over seeds; and each network's test AP, the ensemble's
against its members' mean. Run where ``dvc repro train_gqcnn`` has run with these params:

    python studies/gqcnn_members.py [--members 4] [--out studies/out/members]

Members 1 … K−1 cost (K−1) times ``train_gqcnn``'s time (one network at a time, every thread).
"""
from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np
import pandas as pd
from sklearn.metrics import average_precision_score

from graspaug.config import load_params
from graspaug.experiments.ap import choose_ratios, declared_contrasts
from graspaug.experiments.networks import NetworkJob, initial_weights, network_dir, seed_variants, stream_seeds, train_network, weights_digest
from graspaug.experiments.stats import t_interval
from graspaug.paths import gqcnn_seed_dir
from graspaug.training.gqcnn_data import load_split, shapes_datapoints, test_set


def train_members(params, members: int, out: Path) -> None:
    """Members 1 … ``members``−1 of every network of every seed, one at a time (skipping those on disk)."""
    cfg = params.gqcnn
    split = load_split(list(params.generate.base_sizes), cfg.val_shapes, params.seed)
    variants = seed_variants(params.generate.base_sizes, params.generate.ratios, cfg.augment_base_sizes, cfg.ceiling)
    val, test = shapes_datapoints(split.validation)[0], test_set()[0]
    for seed in cfg.seeds:
        weight_seed, _ = stream_seeds(params.seed, seed)
        for v in variants:  # member 0 must be the pipeline's network
            saved = json.loads((network_dir(gqcnn_seed_dir(seed), v) / "summary.json").read_text())["init_digest"]
            if saved != weights_digest(initial_weights(cfg.net, weight_seed)):
                raise SystemExit(f"models/gqcnn/s{seed}/{v.name} was not trained from member 0's weights: rerun `dvc repro train_gqcnn`")
        for m in range(1, members):
            weight_seed, noise_seed = stream_seeds(params.seed, seed, m)
            init, folder = initial_weights(cfg.net, weight_seed), out / f"s{seed}" / f"m{m}"
            for v in variants:
                if (network_dir(folder, v) / "summary.json").exists():
                    continue
                r = train_network(NetworkJob(v, split, cfg.net, cfg.train, (init,), (noise_seed,), seed, "cpu", folder), val, test)
                print(f"  s{seed} m{m} {v.name}: validation AP {r['validation']['ap']:.4f}, test AP {r['test']['ap']:.4f} "
                      f"({r['train_seconds']:.0f} s)", flush=True)


def member_predictions(seed: int, m: int, v, kind: str, out: Path) -> np.ndarray:
    folder = gqcnn_seed_dir(seed) if m == 0 else out / f"s{seed}" / f"m{m}"
    return np.load(network_dir(folder, v) / f"{kind}_predictions.npy")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--members", type=int, default=4, help="Largest ensemble K.")
    parser.add_argument("--out", type=Path, default=Path("studies/out/members"))
    args = parser.parse_args()
    params = load_params("params.yaml")
    cfg, gen = params.gqcnn, params.generate
    train_members(params, args.members, args.out)
    split = load_split(list(gen.base_sizes), cfg.val_shapes, params.seed)
    val_labels, test_labels = shapes_datapoints(split.validation)[0].labels, test_set()[0].labels
    variants = seed_variants(gen.base_sizes, gen.ratios, cfg.augment_base_sizes, cfg.ceiling)
    rows = []
    for seed in cfg.seeds:
        for v in variants:
            val_p = [member_predictions(seed, m, v, "val", args.out) for m in range(args.members)]
            test_p = [member_predictions(seed, m, v, "test", args.out) for m in range(args.members)]
            for k in range(1, args.members + 1):
                rows.append({"pool": v.pool, "base_size": v.base_size, "ratio": float(v.ratio), "seed": seed, "members": k,
                             "val_ap": average_precision_score(val_labels, np.mean(val_p[:k], axis=0)),
                             "test_ap": average_precision_score(test_labels, np.mean(test_p[:k], axis=0)),
                             "member_test_ap": average_precision_score(test_labels, test_p[k - 1])})
    table = pd.DataFrame(rows)
    args.out.mkdir(parents=True, exist_ok=True)
    table.to_csv(args.out / "ap_by_members.csv", index=False)
    fmt = lambda t: f"{t['mean']:+.4f} [{t['ci_low']:+.4f}, {t['ci_high']:+.4f}]"  # noqa: E731
    print(f"\n{len(cfg.seeds)} seeds; contrast: mean [95% t over seeds], SD over seeds, for ensembles of k members")
    for k in range(1, args.members + 1):
        runs = table[table.members == k]
        chosen = choose_ratios(runs, cfg.augment_base_sizes)
        ap = runs.set_index(["pool", "base_size", "ratio", "seed"]).test_ap
        for c in declared_contrasts(gen.base_sizes, gen.ratios, cfg.augment_base_sizes, chosen):
            per_seed = [sum(w * ap[(*key, s)] for w, key in c.terms) for s in cfg.seeds]
            print(f"k = {k}  {c.name:30s} {fmt(t_interval(per_seed)):32s} SD {np.std(per_seed, ddof=1):.4f}")
    print("\nnetwork test AP by k: ensemble mean over seeds (SD over seeds); the k-th member alone (mean over seeds)")
    for (pool, base, ratio), g in table.groupby(["pool", "base_size", "ratio"], sort=False):
        cells = [f"k={k}: {g[g.members == k].test_ap.mean():.4f} ({g[g.members == k].test_ap.std():.4f})" for k in range(1, args.members + 1)]
        print(f"{pool:9s} {base:4d}-{ratio:g}  " + "  ".join(cells) + f"  | members alone {g.member_test_ap.mean():.4f}")


if __name__ == "__main__":
    main()
