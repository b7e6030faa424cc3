"""Stage ``train_ae``: AutoEncoder (phase 1), then two phase-2 arms from it on the train split:
the AE-Critic and its control (λ = 0: the same epochs, learning rate and batches, no critic).

Outputs: ``models/ae.pt``, ``models/ae_extra.pt`` (control), ``models/ae_critic.pt``, DVCLive
logs in ``metrics/train_ae/{ae,ae_extra,ae_critic}/``, summary ``metrics/train_ae.json``.
"""

from __future__ import annotations

import copy
import dataclasses
import json
import logging
import math
import time

import torch

from graspaug.device import resolve_device
from graspaug.io.atomic import atomic_path
from graspaug.io.checkpoints import save_autoencoder
from graspaug.io.tables import write_json
from graspaug.nets.ae_critic import AutoEncoder, Critic
from graspaug.params.ae import AEParams
from graspaug.params.base import params_model
from graspaug.params.voxelize import VoxelizeParams
from graspaug.paths import (
    AE_CRITIC_MODEL,
    AE_EXTRA_MODEL,
    AE_MODEL,
    SHAPES_TABLE,
    TRAIN_AE_LIVE,
    TRAIN_AE_SUMMARY,
    VOXELS,
    timing_file,
)
from graspaug.stages import StageError
from graspaug.training.autoencoder import (
    critic_separation,
    grids_by_split,
    reconstruction_iou,
    train_ae_critic,
    train_autoencoder,
)

log = logging.getLogger(__name__)

Params = params_model("The params the `train_ae` stage reads.", ae=AEParams, voxelize=VoxelizeParams)


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
    log.info(
        "train_ae: %d train / %d test shapes at %d³ on %s, widths %s",
        len(train),
        len(test),
        cfg.resolution,
        device,
        cfg.widths,
    )
    summary: dict[str, float] = {"n_train": len(train), "n_test": len(test)}
    timing: dict[str, float] = {}

    def logger(live: Live, model: AutoEncoder, critic: Critic | None, iou_every: int, epochs: int, latest: dict):
        def on_epoch(epoch: int, metrics: dict[str, float]) -> None:
            latest.clear()  # the test IoU of the weights as they are now, when this epoch computed it
            for key, value in metrics.items():
                live.log_metric(key, value)
            if (
                (epoch + 1) % iou_every == 0 or epoch + 1 == epochs
            ):  # every `iou_every`-th epoch and the last (each costs a pass over the test split)
                latest["iou_test"] = reconstruction_iou(model, test, device)
                live.log_metric("iou_test", latest["iou_test"])
            if critic is not None:  # held-out real grids vs held-out interpolants
                separation = critic_separation(model, critic, test, device)
                live.log_metric("critic_auc", separation["auc"])
                live.log_metric("critic_real", separation["real_mean"])
                live.log_metric("critic_interp", separation["interp_mean"])
            live.next_step()

        return on_epoch

    def fit_arm(
        name: str, model: AutoEncoder, critic: Critic | None, phase, iou_every: int = 1, epochs: int = 0
    ) -> None:
        with Live(str(TRAIN_AE_LIVE / name), dvcyaml=False, save_dvc_exp=False) as live:
            t0 = time.perf_counter()
            latest: dict[str, float] = {}
            timing[f"{name}_shapes_per_s"] = phase(logger(live, model, critic, iou_every, epochs, latest))
            timing[f"{name}_train_s"] = time.perf_counter() - t0
        # the last epoch already measured the final weights' test IoU (not with zero epochs)
        summary[f"{name}_iou_test"] = (
            latest["iou_test"] if "iou_test" in latest else reconstruction_iou(model, test, device)
        )
        summary[f"{name}_iou_train"] = reconstruction_iou(model, train, device)

    ae = AutoEncoder(cfg)
    fit_arm(
        "ae",
        ae,
        None,
        lambda cb: train_autoencoder(ae, train, tcfg, device, gen, cb),
        iou_every=5,
        epochs=tcfg.epochs_ae,
    )
    save_autoencoder(AE_MODEL, ae, None, dataclasses.asdict(tcfg))

    # phase 2, two arms from the same phase-1 weights and the same random numbers
    phase2_rng = gen.get_state()
    extra = copy.deepcopy(ae)
    fit_arm("ae_extra", extra, None, lambda cb: train_ae_critic(extra, None, train, tcfg, device, gen, cb))
    save_autoencoder(AE_EXTRA_MODEL, extra, None, dataclasses.asdict(dataclasses.replace(tcfg, lam=0.0)))

    gen.set_state(phase2_rng)
    critic = Critic(cfg)
    fit_arm("ae_critic", ae, critic, lambda cb: train_ae_critic(ae, critic, train, tcfg, device, gen, cb))
    save_autoencoder(AE_CRITIC_MODEL, ae, critic, dataclasses.asdict(tcfg))
    summary["critic_auc"] = critic_separation(ae, critic, test, device)["auc"]

    timing["train_s"] = time.perf_counter() - start
    with atomic_path(TRAIN_AE_SUMMARY) as tmp:
        # NaN (e.g. IoU of an empty test split) is not JSON: write null
        tmp.write_text(
            json.dumps({k: round(float(v), 5) if math.isfinite(v) else None for k, v in summary.items()}, indent=2)
            + "\n"
        )
    write_json({k: round(v, 2) for k, v in timing.items()}, timing_file("train_ae"))
    log.info(
        "train_ae: test IoU AE %.3f, control %.3f, AE-Critic %.3f; critic AUC %.3f; %.0f s",
        summary["ae_iou_test"],
        summary["ae_extra_iou_test"],
        summary["ae_critic_iou_test"],
        summary["critic_auc"],
        timing["train_s"],
    )
