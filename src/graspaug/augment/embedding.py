"""2-D maps of latent codes."""

from __future__ import annotations

import numpy as np


def tsne_2d(z: np.ndarray, perplexity: float, seed: int) -> np.ndarray:
    """(N, 2) t-SNE of (N, d) latents (scikit-learn, PCA init, seeded)."""
    from sklearn.manifold import TSNE

    if len(z) < 3:
        return np.zeros((len(z), 2))
    perplexity = min(perplexity, (len(z) - 1) / 3)
    return TSNE(n_components=2, perplexity=perplexity, init="pca", random_state=seed).fit_transform(z)
