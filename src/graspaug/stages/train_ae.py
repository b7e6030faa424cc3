"""Stage ``train_ae``: AutoEncoder (phase 1) then AE-Critic (phase 2) on the train split.

Outputs: ``models/ae.pt``, ``models/ae_critic.pt``, DVCLive logs in
``metrics/train_ae/{ae,ae_critic}/``, summary ``metrics/train_ae.json``.
"""
from __future__ import annotations

import dataclasses
import json
import logging
import math
import time

import torch

from graspaug.config import Params
from graspaug.io.atomic import atomic_path
from graspaug.io.checkpoints import save_autoencoder
from graspaug.device import resolve_device
from graspaug.nets.ae_critic import AutoEncoder, Critic
from graspaug.io.tables import write_json
from graspaug.paths import AE_CRITIC_MODEL, AE_MODEL, SHAPES_TABLE, TRAIN_AE_LIVE, TRAIN_AE_SUMMARY, VOXELS, timing_file
from graspaug.stages import StageError
from graspaug.training.autoencoder import grids_by_split, reconstruction_iou, train_ae_critic, train_autoencoder

log = logging.getLogger(__name__)


def run(params: Params) -> None:
    from dvclive import Live

    start = time.perf_counter()
    torch.manual_seed(params.seed)
    gen = torch.Generator().manual_seed(params.seed)
    device = resolve_device(params.device)
    cfg, tcfg = params.ae.net, params.ae.train
    data = grids_by_split(VOXELS, SHAPES_TABLE)
    train, test = data["train"], data["test"]
    if len(train) < 2:
        raise StageError(f"train_ae needs at least 2 train shapes, the split has {len(train)}")
    log.info("train_ae: %d train / %d test shapes at %d³ on %s, widths %s", len(train), len(test), cfg.resolution, device, cfg.widths)

    ae = AutoEncoder(cfg)
    summary: dict[str, float] = {"n_train": len(train), "n_test": len(test)}

    def logger(live: Live, model: AutoEncoder):
        def on_epoch(epoch: int, metrics: dict[str, float]) -> None:
            for key, value in metrics.items():
                live.log_metric(key, value)
            live.log_metric("iou_train", reconstruction_iou(model, train[:128], device))  # a fixed subset, for speed
            live.log_metric("iou_test", reconstruction_iou(model, test, device))
            live.next_step()

        return on_epoch

    with Live(str(TRAIN_AE_LIVE / "ae"), dvcyaml=False, save_dvc_exp=False) as live:
        t0 = time.perf_counter()
        summary["ae_shapes_per_s"] = train_autoencoder(ae, train, tcfg, device, gen, logger(live, ae))
        summary["ae_train_s"] = time.perf_counter() - t0
    summary["ae_iou_test"] = reconstruction_iou(ae, test, device)
    summary["ae_iou_train"] = reconstruction_iou(ae, train, device)
    save_autoencoder(AE_MODEL, ae, None, dataclasses.asdict(tcfg))

    critic = Critic(cfg)
    with Live(str(TRAIN_AE_LIVE / "ae_critic"), dvcyaml=False, save_dvc_exp=False) as live:
        t0 = time.perf_counter()
        summary["ae_critic_shapes_per_s"] = train_ae_critic(ae, critic, train, tcfg, device, gen, logger(live, ae))
        summary["ae_critic_train_s"] = time.perf_counter() - t0
    summary["ae_critic_iou_test"] = reconstruction_iou(ae, test, device)
    summary["ae_critic_iou_train"] = reconstruction_iou(ae, train, device)
    save_autoencoder(AE_CRITIC_MODEL, ae, critic, dataclasses.asdict(tcfg))

    summary["train_s"] = time.perf_counter() - start
    timing = {k: round(summary.pop(k), 2) for k in ("ae_shapes_per_s", "ae_train_s", "ae_critic_shapes_per_s", "ae_critic_train_s", "train_s")}
    with atomic_path(TRAIN_AE_SUMMARY) as tmp:
        # NaN (e.g. IoU of an empty test split) is not JSON: write null
        tmp.write_text(json.dumps({k: round(float(v), 5) if math.isfinite(v) else None for k, v in summary.items()}, indent=2) + "\n")
    write_json(timing, timing_file("train_ae"))
    log.info(
        "train_ae: test IoU AE %.3f, AE-Critic %.3f; %.0f s (%.1f / %.1f shapes/s)",
        summary["ae_iou_test"], summary["ae_critic_iou_test"], timing["train_s"], timing["ae_shapes_per_s"], timing["ae_critic_shapes_per_s"],
    )
