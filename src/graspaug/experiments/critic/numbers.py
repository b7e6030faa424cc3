"""The critic study's numbers: random interpolation pairs, their decodes, outlier percentages and the paired contrasts
between models (bootstrap over pairs)."""

from __future__ import annotations

import numpy as np
import torch

from graspaug.experiments.stats import PairBootstrap, headline, mean_interval, paired_contrast
from graspaug.geometry.clusters import outlier_percentage
from graspaug.nets.ae_critic import AutoEncoder, decode, encode
from graspaug.training.autoencoder import occupied

# the three models of the study, in the order they are decoded, tabled and drawn
MODEL_LABELS = {"ae": "AE", "ae_extra": "AE + extra epochs (λ = 0)", "ae_critic": "AE-Critic"}


# paired contrasts: name → (model A, model B), A − B
CONTRASTS = {
    "critic_vs_control": ("ae_critic", "ae_extra"),
    "critic_vs_ae": ("ae_critic", "ae"),
    "control_vs_ae": ("ae_extra", "ae"),
}


def random_pairs(n: int, n_shapes: int, n_pairs: int, rng: np.random.Generator) -> np.ndarray:
    """(P, 2) index pairs: ``n_shapes`` of ``n`` drawn at random, paired off at random, first ``n_pairs``."""
    chosen = rng.choice(n, size=min(n, n_shapes), replace=False)
    pairs = rng.permutation(chosen)[: 2 * (len(chosen) // 2)].reshape(-1, 2)
    return pairs[:n_pairs]


def interpolate(z: np.ndarray, pairs: np.ndarray, alphas: np.ndarray) -> np.ndarray:
    """(P, A, d) latents ``(1 − α) z_a + α z_b`` for every pair and weight."""
    a, b = z[pairs[:, 0]][:, None], z[pairs[:, 1]][:, None]
    return (1 - alphas[None, :, None]) * a + alphas[None, :, None] * b


def decoded_interpolations(
    ae: AutoEncoder, z: np.ndarray, pairs: np.ndarray, alphas: np.ndarray, threshold: float, device: torch.device
) -> np.ndarray:
    """(P, A, R, R, R) bool: the pairs of latents ``z`` (N, d) interpolated at ``alphas`` (A,), decoded, their inside
    (:func:`~graspaug.training.autoencoder.occupied`: occupancy above ``threshold``, or a negative signed distance)."""
    grids = decode(ae, interpolate(z, pairs, alphas).reshape(-1, z.shape[1]), device)
    return occupied(grids, ae.cfg.output, threshold).reshape(len(pairs), len(alphas), *grids.shape[1:])


def outlier_table(decoded: np.ndarray) -> np.ndarray:
    """(P, A) outlier % of every decoded grid (P, A, R, R, R); NaN for an empty grid."""
    flat = decoded.reshape(-1, *decoded.shape[2:])
    return np.array([outlier_percentage(g) for g in flat]).reshape(decoded.shape[:2])


def summarize(pct: np.ndarray, boot: PairBootstrap, level: float = 0.95) -> list[dict[str, float | None]]:
    """Per α (column of ``pct`` (P, A), outlier %): mean outlier % over the pairs with a grid
    and its bootstrap ``level`` interval over pairs."""
    return [mean_interval(pct[:, i], boot, level) for i in range(pct.shape[1])]


def outlier_contrast(
    pct_a: np.ndarray, pct_b: np.ndarray, boot: PairBootstrap, level: float = 0.95
) -> list[dict[str, float | None]]:
    """Per α: mean over pairs of ``pct_a − pct_b`` (both (P, A) outlier %, the same pairs) with its
    bootstrap interval; a pair empty under either model is left out."""
    return [paired_contrast(pct_a[:, i], pct_b[:, i], boot, level) for i in range(pct_a.shape[1])]


def interpolant_contrast(
    pct_a: np.ndarray, pct_b: np.ndarray, keys: list[str], boot: PairBootstrap, level: float = 0.95
) -> dict[str, float | None]:
    """The study's headline: per pair, the mean over the interpolants (0 < α < 1 of ``keys``; every α
    if none) of ``pct_a − pct_b`` (both (P, A) outlier %, the same pairs; an empty grid left out), then
    its mean over pairs with the bootstrap interval (percentage points)."""
    columns = [i for i, k in enumerate(keys) if 0 < float(k) < 1] or list(range(len(keys)))
    diff = pct_a[:, columns] - pct_b[:, columns]  # (P, A')
    finite = np.isfinite(diff)
    counts = finite.sum(axis=1)
    sums = np.where(finite, diff, 0.0).sum(axis=1)
    per_pair = np.divide(sums, counts, out=np.full(len(diff), np.nan), where=counts > 0)  # (P,)
    return mean_interval(per_pair, boot, level)


def model_interpolations(
    ae: AutoEncoder,
    grids: torch.Tensor,
    pairs: np.ndarray,
    examples: np.ndarray,
    alphas: np.ndarray,
    example_alphas: np.ndarray,
    threshold: float,
    device: torch.device,
) -> tuple[np.ndarray, np.ndarray]:
    """One model's part of the study: the train ``grids`` (N, 1, R, R, R) uint8, encoded once, interpolated
    and decoded twice.

    Returns
    -------
    pct : (P, A) float — outlier % of every pair of ``pairs`` (P, 2) decoded at ``alphas`` (A,)
        (NaN for an empty grid; see :func:`outlier_table`).
    sequences : (E, S, R, R, R) bool — the ``examples`` (E, 2) pairs decoded at ``example_alphas`` (S,),
        thresholded at ``threshold`` (occupancy probability).
    """
    z = encode(ae, grids, device)
    pct = outlier_table(decoded_interpolations(ae, z, pairs, alphas, threshold, device))
    return pct, decoded_interpolations(ae, z, examples, example_alphas, threshold, device)


def finite_or_none(values: dict[str, float]) -> dict[str, float | None]:
    """``values`` with every non-finite number (NaN, ±inf: not JSON) replaced by None."""
    return {k: v if np.isfinite(v) else None for k, v in values.items()}


def study_metrics(
    pct: dict[str, np.ndarray], boot: PairBootstrap, keys: list[str], critic: dict, n_bootstrap: int
) -> dict:
    """The critic study's results, every model and α (the stage's report; its metrics: :func:`study_headline`).

    Parameters
    ----------
    pct : model → (P, A) outlier % (NaN: empty grid), every model on the same pairs, in
        :data:`MODEL_LABELS` order.
    boot : the pairs' bootstrap, shared by every model (the contrasts stay paired).
    keys : (A,) the α's names (``"0.10"``).
    critic : the AE-Critic's :func:`~graspaug.training.autoencoder.critic_separation`, non-finite as None.
    n_bootstrap : resamples in ``boot`` (reported).

    Returns
    -------
    dict — ``n_pairs``, ``n_decoded_per_model``, ``n_bootstrap``, ``critic_auc``, ``critic``,
    ``outlier_pct`` (model → α key → mean %), ``outlier_pct_ci`` (model → α key →
    :func:`~graspaug.experiments.stats.mean_interval` dict), ``contrast`` (:data:`CONTRASTS` name → α key →
    :func:`~graspaug.experiments.stats.paired_contrast` dict, percentage points), ``critic_vs_control_interpolants``
    (:func:`interpolant_contrast` of the AE-Critic against the control) and ``empty_grids`` (model → count).
    """
    summary = {name: dict(zip(keys, summarize(pct[name], boot))) for name in pct}
    contrast = {c: dict(zip(keys, outlier_contrast(pct[a], pct[b], boot))) for c, (a, b) in CONTRASTS.items()}
    return {
        "n_pairs": int(len(pct["ae"])),
        "n_decoded_per_model": int(pct["ae"].size),
        "n_bootstrap": n_bootstrap,
        "critic_auc": critic["auc"],
        "critic": critic,
        "outlier_pct": {name: {k: v["mean"] for k, v in summary[name].items()} for name in pct},
        "outlier_pct_ci": summary,
        "contrast": contrast,
        "critic_vs_control_interpolants": interpolant_contrast(pct["ae_critic"], pct["ae_extra"], keys, boot),
        "empty_grids": {name: int(np.isnan(pct[name]).sum()) for name in pct},
    }


def study_headline(study: dict) -> dict[str, float | None]:
    """The stage's metrics from :func:`study_metrics`: the AE-Critic − control outlier difference over the
    interpolants (``mean``, 95% interval ``lo``, ``hi``; percentage points) and the critic's held-out ROC ``auc``."""
    auc = study["critic_auc"]
    return {**headline(study["critic_vs_control_interpolants"]), "auc": None if auc is None else round(auc, 5)}
