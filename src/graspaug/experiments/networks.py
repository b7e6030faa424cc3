"""Training every GQ-CNN of one seed as a paired set: the same initial weights, the same noise
stream and the same validation shapes for every variant, so differences between variants
of a seed are paired (common random numbers); seeds are the replicates.

A seed's networks live in ``models/gqcnn/s<seed>/<pool>/<B>-<R>/`` (``ceiling/`` for the
ceiling): ``model.pt`` (config, weights, summary), ``summary.json``, ``history.csv``
(validation AP per evaluation), ``test_predictions.npy`` and ``val_predictions.npy``
(P(success) per datapoint, rows in ``test_rows.npy`` / ``val_rows.npy`` of the seed folder).
"""
from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd
import torch

from graspaug.io.checkpoints import finish_gqcnn_card, save_gqcnn
from graspaug.nets.gqcnn import GQCNN
from graspaug.nets.settings import GQCNNConfig
from graspaug.training.gqcnn import GraspArrays, classification_metrics, predict, train_gqcnn
from graspaug.training.gqcnn_data import ExperimentSplit, Variant, shapes_datapoints, test_set, training_set
from graspaug.training.settings import TrainSettings


def seed_variants(base_sizes, ratios, augment_base_sizes, ceiling: bool) -> list[Variant]:
    """Every network of a seed: 1:0 at every base size; targeted, random and real at every
    nonzero ratio of ``augment_base_sizes``; the ceiling."""
    out = [Variant("targeted", b, 0.0) for b in base_sizes]
    out += [Variant(p, b, float(r)) for p in ("targeted", "random", "real") for b in augment_base_sizes for r in ratios if r > 0]
    return out + ([Variant("ceiling")] if ceiling else [])


def stream_seeds(global_seed: int, seed: int) -> tuple[int, int]:
    """(initial-weights seed, noise-and-batch-order seed) of training seed ``seed``."""
    base = global_seed * 1_000_003 + 7919 * seed
    return base, base + 1


def initial_weights(config: GQCNNConfig, weight_seed: int) -> dict[str, torch.Tensor]:
    """The weights every network of a seed starts from."""
    torch.manual_seed(weight_seed)
    return GQCNN(config).state_dict()


def weights_digest(state: dict[str, torch.Tensor]) -> str:
    """SHA-256 (first 16 hex digits) of a state dict's tensors, in key order."""
    digest = hashlib.sha256()
    for name in sorted(state):
        digest.update(name.encode())
        digest.update(state[name].detach().cpu().contiguous().numpy().tobytes())
    return digest.hexdigest()[:16]


@dataclass(frozen=True)
class NetworkJob:
    """One network of a seed (a worker's unit of work)."""

    variant: Variant
    split: ExperimentSplit
    net: GQCNNConfig
    train: TrainSettings
    init: dict
    noise_seed: int
    seed: int
    device: str
    out_dir: Path
    card: dict | None = None  # the model card's data part (graspaug.io.checkpoints.gqcnn_card)


def network_dir(seed_dir: Path, variant: Variant) -> Path:
    return seed_dir / variant.name


def train_network(job: NetworkJob, val: GraspArrays | None = None, test: GraspArrays | None = None) -> dict:
    """Train one network from the seed's initial weights; write its folder; return its summary.
    ``val`` / ``test``: the seed's validation and test datapoints (read here when not given)."""
    device = torch.device(job.device)
    train, info = training_set(job.variant, job.split)
    val = val if val is not None else shapes_datapoints(job.split.validation)[0]
    test = test if test is not None else test_set()[0]
    net = GQCNN(job.net)
    net.load_state_dict(job.init)
    gen = torch.Generator().manual_seed(job.noise_seed)
    history: list[dict] = []
    fit = train_gqcnn(net, train, val, job.train, device, gen, on_log=lambda step, m: history.append({"step": step, **m}), progress=False)
    val_p = fit["val_predictions"] if fit["val_predictions"] is not None else predict(net, val, device, job.train.eval_batch)  # the kept weights
    test_p = predict(net, test, device, job.train.eval_batch)
    rounded = lambda d: {k: (round(v, 5) if isinstance(v, float) else v) for k, v in d.items()}  # noqa: E731
    summary = {"pool": job.variant.pool, "base_size": job.variant.base_size, "ratio": job.variant.ratio, "seed": job.seed,
               "validation": rounded(classification_metrics(val.labels, val_p)), "test": rounded(classification_metrics(test.labels, test_p)),
               "train": {**info, "steps": fit["steps"], "best_step": fit["best_step"], "batch_size": job.train.batch_size},
               "parameters": net.describe()["parameters"], "init_digest": weights_digest(job.init), "noise_seed": job.noise_seed}
    folder = network_dir(job.out_dir, job.variant)
    folder.mkdir(parents=True, exist_ok=True)
    save_gqcnn(folder / "model.pt", net, summary, finish_gqcnn_card(job.card, summary))
    np.save(folder / "test_predictions.npy", test_p)
    np.save(folder / "val_predictions.npy", val_p)
    pd.DataFrame(history).to_csv(folder / "history.csv", index=False)
    (folder / "summary.json").write_text(json.dumps(summary, indent=2) + "\n")
    return {**summary, "train_seconds": fit["train_seconds"], "samples_per_second": fit["samples_per_second"]}


def seed_table(summaries: list[dict]) -> dict:
    """The seed's metrics file: pool → base size → ratio → validation / test AP and ROC AUC, steps."""
    out: dict = {}
    for s in summaries:
        key = ("ceiling", "all", "-") if s["pool"] == "ceiling" else (s["pool"], str(s["base_size"]), f"{s['ratio']:g}")
        out.setdefault(key[0], {}).setdefault(key[1], {})[key[2]] = {
            "val_ap": s["validation"]["ap"], "test_ap": s["test"]["ap"], "test_roc_auc": s["test"]["roc_auc"],
            "datapoints": s["train"]["datapoints"], "steps": s["train"]["steps"], "best_step": s["train"]["best_step"]}
    return out


def read_history(seed_dir: Path, variants: list[Variant]) -> pd.DataFrame:
    """Validation AP per evaluation of every network of a seed: step, network, val_ap."""
    frames = [pd.read_csv(network_dir(seed_dir, v) / "history.csv").assign(network=v.name) for v in variants]
    return pd.concat(frames, ignore_index=True)[["network", "step", "val_ap", "loss", "lr"]] if frames else pd.DataFrame()
