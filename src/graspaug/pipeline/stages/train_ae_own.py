"""Stage ``train_ae_own``: for one augmented base set of B train shapes (``train_ae_own@50`` …), the own pool's
AutoEncoder-Critic, trained on that base set's voxel grids alone (the ``own`` pool of ``gqcnn.pools``: the targeted
recipe with no geometry from beyond the base set).

The two phases of ``train_ae`` (AutoEncoder, then AE-Critic from it; no λ = 0 control) with ``ae.net`` and
``ae.train`` but the epochs: ``generate.own`` names them, or by default they take as many SGD steps on the B shapes
as the main AE-Critic's took on the train split. Its reconstruction IoU is measured on the base set and on the test
split, beside the main AE-Critic's on the same grids. With ``own`` not in ``gqcnn.pools`` it trains nothing and says
so in its summary.

Outputs: ``models/ae_own/<B>/`` (``ae_critic.pt``, whose train_params name the shapes it trained on: ``train_ids``;
``latents.parquet``, the base set encoded by it; ``summary.json``; DVCLive logs in ``live/``),
``metrics/train_ae_own/<B>.json`` (shapes, IoU on the base set: its own and the main AE-Critic's),
``reports/timing/train_ae_own/<B>.json``.
"""

from __future__ import annotations

import logging
import time

import numpy as np
import pandas as pd

from graspaug.augment.pools import base_ids
from graspaug.device import resolve_device
from graspaug.io.atomic import atomic_path
from graspaug.io.checkpoints import load_autoencoder, save_autoencoder
from graspaug.io.tables import read_table, write_json, write_table
from graspaug.nets.ae_critic import encode
from graspaug.pipeline import paths
from graspaug.pipeline.params.ae import AEParams
from graspaug.pipeline.params.base import params_model
from graspaug.pipeline.params.generate import GenerateParams
from graspaug.pipeline.params.gqcnn import GQCNNParams
from graspaug.pipeline.params.voxelize import VoxelizeParams
from graspaug.pipeline.stages import StageError
from graspaug.training.ae_arms import fit_ae_critic, rounded_summary
from graspaug.training.autoencoder import checkpoint_params, reconstruction_iou, step_matched, voxel_grids
from graspaug.training.settings import networks_at

log = logging.getLogger(__name__)

Params = params_model(
    "The params the `train_ae_own` stage reads.",
    ae=AEParams,
    voxelize=VoxelizeParams,
    generate=GenerateParams,
    gqcnn=GQCNNParams,
)
HEADLINE = ("shapes", "iou_base", "main_iou_base")  # few keys: `dvc metrics show` has a column per key of any file


def run(params: Params, base_size: int) -> None:
    start, gq, b = time.perf_counter(), params.gqcnn, base_size
    if b not in gq.augment_base_sizes:
        raise StageError(f"base size {b} is not in gqcnn.augment_base_sizes {list(gq.augment_base_sizes)}")
    wanted = networks_at(gq.networks, b)
    listed = wanted is None or "own" in wanted  # gqcnn.networks lists no own network at this B: nothing to train
    summary: dict = {"base_size": b, "trained": "own" in gq.pools and listed}
    with atomic_path(paths.ae_own_dir(b), directory=True) as folder:
        if summary["trained"]:
            summary |= train_own(params, b, folder)
        else:
            summary["why"] = "own is not in gqcnn.pools" if listed else f"gqcnn.networks lists no own network at {b}"
        write_json(summary, folder / paths.ae_own_summary(b).name)
    write_json({k: summary[k] for k in HEADLINE} if summary["trained"] else {"shapes": 0}, paths.ae_own_metrics(b))
    seconds = round(time.perf_counter() - start, 1)
    write_json({"seconds": seconds}, paths.timing_file("train_ae_own", str(b)))
    if summary["trained"]:
        figures = tuple(summary[k] for k in ("iou_base", "main_iou_base", "iou_test", "main_iou_test")) + (seconds,)
        log.info("train_ae_own %d: IoU base set %s (main AE-Critic %s), test %s (main %s); %.0f s", b, *figures)
    else:
        log.info("train_ae_own %d: %s, nothing to train", b, summary["why"])


def train_own(params: Params, base_size: int, folder) -> dict:
    """Train base set ``base_size``'s own AE-Critic into ``folder``; its figures for the summary."""
    device, net, own = resolve_device(params.device), params.ae.net, params.generate.own
    ids = base_ids(read_table(paths.SHAPES_TABLE), params.generate.base_sizes, base_size, params.data_seed)
    shape_ids, split, grids = voxel_grids(paths.VOXELS, paths.SHAPES_TABLE, net.output)
    row, n_train = {s: i for i, s in enumerate(shape_ids)}, int((split == "train").sum())
    base, test = grids[[row[s] for s in ids]], grids[split == "test"]
    cfg = step_matched(params.ae.train, n_train, len(ids), own.epochs_ae, own.epochs_critic)
    epochs = {"epochs_ae": cfg.epochs_ae, "epochs_critic": cfg.epochs_critic}
    log.info("train_ae_own %d: %d of %d train shapes, %d + %d epochs", base_size, len(ids), n_train, *epochs.values())
    ae, critic, arms = fit_ae_critic(folder / "live", base, test, net, cfg, device, params.seed)
    trained = checkpoint_params(cfg, device) | {"train_ids": [str(s) for s in ids]}  # what generate checks
    save_autoencoder(folder / paths.ae_own_model(base_size).name, ae, critic, trained)
    z = list(encode(ae, base, device).astype(np.float32))
    write_table(pd.DataFrame({"shape_id": ids, "z": z}), folder / paths.ae_own_latents(base_size).name)
    main, _, _ = load_autoencoder(paths.AE_CRITIC_MODEL, net)  # the main AE-Critic on the same grids
    figures = {"iou_base": arms.summary["ae_critic_iou_train"], "iou_test": arms.summary["ae_critic_iou_test"]}
    figures |= {
        "main_iou_base": reconstruction_iou(main, base, device),
        "main_iou_test": reconstruction_iou(main, test, device),
    }
    out = {"train_ids": trained["train_ids"], "shapes": len(ids)} | rounded_summary(arms.summary | figures)
    return out | {"timing": rounded_summary(arms.timing)} | epochs


if __name__ == "__main__":
    import typer

    from graspaug.pipeline.entry import stage_main

    stage_main(__spec__.name, base_size=(int, typer.Option(..., "--base-size", "-b", help="The base set size B.")))
