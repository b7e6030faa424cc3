"""Stage ``train_gqcnn``: one GQ-CNN for one base size B, augmentation ratio R, pool and seed.

Training set: the rendered datapoints of the B base shapes (``data/gqcnn/original``, shapes
of ``data/generated/B/base.parquet``) plus those of the first round(R × B) shapes of B's
``targeted`` (or ``random``) pool (``data/gqcnn/gen_B``); a ``val_fraction`` of its views is
held out for the validation curves. Test set: every test-split datapoint of
``data/gqcnn/original``. Budget rule: ``gqcnn.steps`` SGD steps for every variant.

Outputs: ``models/gqcnn/<pool>/<B>-<R>-s<seed>/`` (``model.pt``: config, weights, training
summary; ``summary.json``; ``timing.json``: seconds and samples/s; ``test_predictions.npy``:
P(success) per test datapoint and ``test_rows.npy``: their rows in the original index),
``metrics/gqcnn/<pool>/<B>-<R>-s<seed>.json`` (test AP, accuracy, ROC AUC; stable keys for
``dvc metrics diff``) and the DVCLive curves in ``metrics/gqcnn/<pool>/<B>-<R>-s<seed>/``.
"""
from __future__ import annotations

import dataclasses
import json
import logging
import time

import numpy as np
import torch

from graspaug.config import Params
from graspaug.device import resolve_device
from graspaug.io.atomic import atomic_path
from graspaug.io.tables import write_json
from graspaug.nets.gqcnn import GQCNN
from graspaug.paths import gqcnn_live, gqcnn_metrics, gqcnn_model_dir
from graspaug.stages import StageError
from graspaug.training.gqcnn import classification_metrics, predict, train_gqcnn
from graspaug.training.gqcnn_data import POOLS, held_out_views, test_set, training_set

log = logging.getLogger(__name__)

def run(params: Params, base_size: int, ratio: float, pool: str = "targeted", seed: int = 0) -> None:
    cfg = params.gqcnn
    if pool not in POOLS:
        raise StageError(f"unknown pool {pool!r}; known: {', '.join(POOLS)}")
    if base_size not in params.generate.base_sizes:
        raise StageError(f"base size {base_size} is not in generate.base_sizes {list(params.generate.base_sizes)}")
    if float(ratio) not in params.generate.ratios:
        raise StageError(f"ratio {ratio} is not in generate.ratios {list(params.generate.ratios)}")
    start = time.perf_counter()
    device = resolve_device(params.device)
    train, keys, info = training_set(base_size, ratio, pool)
    if len(train) < 2:
        raise StageError(f"training set of {base_size}-{ratio} ({pool}) has {len(train)} datapoints; render the corpora first")
    if train.labels.min() == train.labels.max():
        log.warning("train_gqcnn %s %d-%s: all %d training datapoints have label %d; the network cannot learn to rank",
                    pool, base_size, ratio, len(train), int(train.labels[0]))
    is_val = held_out_views(keys, cfg.val_fraction, params.seed, seed)
    val, fit = train.subset(np.flatnonzero(is_val)), train.subset(np.flatnonzero(~is_val))
    test, test_rows = test_set()

    torch.manual_seed(params.seed * 1_000_003 + seed)
    net = GQCNN(cfg.net)
    gen = torch.Generator().manual_seed(params.seed * 1_000_003 + seed + 1)
    from dvclive import Live

    live_dir = gqcnn_live(pool, base_size, ratio, seed)
    log.info("train_gqcnn %s %d-%s seed %d: %d train / %d val datapoints (%d base + %d generated shapes), %d test, %s on %s",
             pool, base_size, ratio, seed, len(fit), len(val), info["base_shapes"], info["generated_shapes"], len(test), net.describe(), device)
    with Live(str(live_dir), dvcyaml=False, save_dvc_exp=False) as live:
        def on_log(step: int, metrics: dict[str, float]) -> None:
            live.step = step  # x axis: SGD steps
            for name, value in metrics.items():
                live.log_metric(name, value)

        speed = train_gqcnn(net, fit, val if len(val) else None, cfg.train, device, gen, on_log)
    probability = predict(net, test, device)
    scores = classification_metrics(test.labels, probability)
    summary = {  # the metrics file: stable keys, no timings (they would show in every `dvc metrics diff`)
        "pool": pool, "base_size": base_size, "ratio": float(ratio), "seed": seed,
        "test": {k: (round(v, 5) if isinstance(v, float) else v) for k, v in scores.items()},
        "train": {**info, "fit_datapoints": len(fit), "val_datapoints": len(val)},
        "steps": cfg.train.steps, "batch_size": cfg.train.batch_size, "parameters": net.describe()["parameters"],
    }
    timing = {"samples_per_second": round(speed["samples_per_second"], 1), "seconds": round(time.perf_counter() - start, 1)}
    with atomic_path(gqcnn_model_dir(pool, base_size, ratio, seed), directory=True) as folder:
        torch.save({"config": dataclasses.asdict(net.config), "state_dict": net.state_dict(), "summary": summary}, folder / "model.pt")
        (folder / "timing.json").write_text(json.dumps(timing) + "\n")
        np.save(folder / "test_predictions.npy", probability)
        np.save(folder / "test_rows.npy", test_rows)
        (folder / "summary.json").write_text(json.dumps(summary, indent=2) + "\n")
    write_json(summary, gqcnn_metrics(pool, base_size, ratio, seed))
    log.info("train_gqcnn %s %d-%s seed %d: test AP %.4f, accuracy %.4f, ROC AUC %.4f; %.0f samples/s, %.1f s", pool, base_size, ratio, seed,
             scores["ap"] or float("nan"), scores["accuracy"], scores["roc_auc"] or float("nan"), timing["samples_per_second"], timing["seconds"])

