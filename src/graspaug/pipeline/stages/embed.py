"""Stage ``embed``: the AE-Critic latent z of every shape, and a t-SNE map of them.

Outputs: ``data/latents.parquet`` (``shape_id``, ``split``, ``z``: 128 float32),
``reports/embed/tsne.csv`` (for ``dvc plots``) and ``reports/embed/tsne.png``.
"""

from __future__ import annotations

import logging

import numpy as np
import pandas as pd

from graspaug.augment.embedding import tsne_2d
from graspaug.device import resolve_device
from graspaug.io.checkpoints import load_autoencoder
from graspaug.io.tables import write_csv, write_table
from graspaug.nets.ae_critic import encode
from graspaug.pipeline.params.ae import AEParams
from graspaug.pipeline.params.base import params_model
from graspaug.pipeline.params.embed import EmbedParams
from graspaug.pipeline.paths import AE_CRITIC_MODEL, LATENTS, SHAPES_TABLE, TSNE_CSV, TSNE_PNG, VOXELS
from graspaug.plots import scatter_2d
from graspaug.training.autoencoder import voxel_grids

log = logging.getLogger(__name__)

Params = params_model("The params the `embed` stage reads.", ae=AEParams, embed=EmbedParams)


def run(params: Params) -> None:
    device = resolve_device(params.device)
    ae, _, _ = load_autoencoder(AE_CRITIC_MODEL, params.ae.net)
    shape_ids, split, grids = voxel_grids(VOXELS, SHAPES_TABLE, params.ae.net.output)
    z = encode(ae, grids, device)

    latents = pd.DataFrame({"shape_id": shape_ids, "split": split, "z": list(z.astype(np.float32))})
    write_table(latents, LATENTS)

    xy = tsne_2d(z, params.embed.perplexity, params.seed)
    write_csv(pd.DataFrame({"shape_id": shape_ids, "split": split, "x": xy[:, 0], "y": xy[:, 1]}), TSNE_CSV)
    scatter_2d(xy, split, TSNE_PNG, f"t-SNE of AE-Critic latents ({len(z)} shapes)")
    log.info("embed: %d latents of size %d, t-SNE written", len(z), z.shape[1])


if __name__ == "__main__":
    from graspaug.pipeline.entry import stage_main

    stage_main(__spec__.name)
