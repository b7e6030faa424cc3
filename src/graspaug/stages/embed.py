"""Stage ``embed``: the AE-Critic latent z of every shape, and a t-SNE map of them.

Outputs: ``data/latents.parquet`` (``shape_id``, ``split``, ``z``: 128 float32),
``reports/embed/tsne.csv`` (for ``dvc plots``) and ``reports/embed/tsne.png``.
"""
from __future__ import annotations

import logging

import numpy as np
import pandas as pd

from graspaug.config import Params
from graspaug.io.checkpoints import load_autoencoder
from graspaug.io.tables import write_csv, write_table
from graspaug.plots import scatter_2d
from graspaug.paths import AE_CRITIC_MODEL, LATENTS, TSNE_CSV, TSNE_PNG
from graspaug.stages.train_ae import load_grids, net_config
from graspaug.training.autoencoder import encode, resolve_device

log = logging.getLogger(__name__)


def tsne_2d(z: np.ndarray, perplexity: float, seed: int) -> np.ndarray:
    """(N, 2) t-SNE of (N, d) latents (scikit-learn, PCA init, seeded)."""
    from sklearn.manifold import TSNE

    if len(z) < 3:
        return np.zeros((len(z), 2))
    perplexity = min(perplexity, (len(z) - 1) / 3)
    return TSNE(n_components=2, perplexity=perplexity, init="pca", random_state=seed).fit_transform(z)


def run(params: Params) -> None:
    device = resolve_device(params.device)
    ae, _, _ = load_autoencoder(AE_CRITIC_MODEL, net_config(params))
    shape_ids, split, grids = load_grids()
    z = encode(ae, grids, device)

    latents = pd.DataFrame({"shape_id": shape_ids, "split": split, "z": list(z.astype(np.float32))})
    write_table(latents, LATENTS)

    xy = tsne_2d(z, params.embed.perplexity, params.seed)
    write_csv(pd.DataFrame({"shape_id": shape_ids, "split": split, "x": xy[:, 0], "y": xy[:, 1]}), TSNE_CSV)
    scatter_2d(xy, split, TSNE_PNG, f"t-SNE of AE-Critic latents ({len(z)} shapes)")
    log.info("embed: %d latents of size %d, t-SNE written", len(z), z.shape[1])
