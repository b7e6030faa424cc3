"""Stage ``train_ae``: AutoEncoder (phase 1), then two phase-2 arms from it on the train split:
the AE-Critic and its control (λ = 0: the same epochs, learning rate and batches, no critic).

Outputs: ``models/ae.pt``, ``models/ae_extra.pt`` (control), ``models/ae_critic.pt``, DVCLive
logs in ``metrics/train_ae/{ae,ae_extra,ae_critic}/``, the headline ``metrics/train_ae.json`` (test IoU per arm, the
critic's AUC), every figure in ``reports/train_ae/summary.json``.
"""

from __future__ import annotations

import copy
import logging
import time

import torch

from graspaug.device import log_precision, resolve_device
from graspaug.io.checkpoints import save_autoencoder
from graspaug.io.tables import write_json
from graspaug.nets.ae_critic import AutoEncoder, Critic
from graspaug.pipeline.params.ae import AEParams
from graspaug.pipeline.params.base import params_model
from graspaug.pipeline.params.voxelize import VoxelizeParams
from graspaug.pipeline.paths import (
    AE_CRITIC_MODEL,
    AE_EXTRA_MODEL,
    AE_MODEL,
    SHAPES_TABLE,
    TRAIN_AE_LIVE,
    TRAIN_AE_REPORT,
    TRAIN_AE_SUMMARY,
    VOXELS,
    timing_file,
)
from graspaug.pipeline.stages import StageError
from graspaug.training.ae_arms import ArmTrainer, rounded_summary, summary_headline
from graspaug.training.autoencoder import (
    checkpoint_params,
    critic_separation,
    grids_by_split,
    train_ae_critic,
    train_autoencoder,
)

log = logging.getLogger(__name__)

Params = params_model("The params the `train_ae` stage reads.", ae=AEParams, voxelize=VoxelizeParams)


def run(params: Params) -> None:
    start = time.perf_counter()
    torch.manual_seed(params.seed)
    gen = torch.Generator().manual_seed(params.seed)
    device = resolve_device(params.device)
    cfg, tcfg = params.ae.net, params.ae.train
    data = grids_by_split(VOXELS, SHAPES_TABLE, cfg.output)
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
    train_params = checkpoint_params(tcfg, device)  # precision as resolved here
    log_precision("train_ae", "ae.train.precision", tcfg.precision, device)
    arms = ArmTrainer(TRAIN_AE_LIVE, train, test, device)
    summary, timing = arms.summary, arms.timing

    ae = AutoEncoder(cfg)
    arms.fit("ae", ae, None, lambda cb: train_autoencoder(ae, train, tcfg, device, gen, cb), 5, tcfg.epochs_ae)
    save_autoencoder(AE_MODEL, ae, None, train_params)

    # phase 2, two arms from the same phase-1 weights and the same random numbers
    phase2_rng = gen.get_state()
    extra = copy.deepcopy(ae)
    arms.fit("ae_extra", extra, None, lambda cb: train_ae_critic(extra, None, train, tcfg, device, gen, cb))
    save_autoencoder(AE_EXTRA_MODEL, extra, None, train_params | {"lam": 0.0})

    gen.set_state(phase2_rng)
    critic = Critic(cfg)
    arms.fit("ae_critic", ae, critic, lambda cb: train_ae_critic(ae, critic, train, tcfg, device, gen, cb))
    save_autoencoder(AE_CRITIC_MODEL, ae, critic, train_params)
    summary["critic_auc"] = critic_separation(ae, critic, test, device)["auc"]

    timing["train_s"] = time.perf_counter() - start
    write_json(rounded_summary(summary), TRAIN_AE_REPORT)
    write_json(summary_headline(rounded_summary(summary)), TRAIN_AE_SUMMARY)
    write_json({k: round(v, 2) for k, v in timing.items()}, timing_file("train_ae"))
    log.info(
        "train_ae: test IoU AE %.3f, control %.3f, AE-Critic %.3f; critic AUC %.3f; %.0f s",
        summary["ae_iou_test"],
        summary["ae_extra_iou_test"],
        summary["ae_critic_iou_test"],
        summary["critic_auc"],
        timing["train_s"],
    )


if __name__ == "__main__":
    from graspaug.pipeline.entry import stage_main

    stage_main(__spec__.name)
