"""The critic study (paper Section IV-B) with uncertainty: outliers of decoded interpolations,
per model and α, with bootstrap intervals over pairs, and paired contrasts between models.

Every model decodes the *same* pairs at the same weights, so a contrast is a paired
difference: pair p's outlier % under model A minus under model B, averaged over pairs.
Intervals are percentile bootstraps that resample pairs (one
:class:`~graspaug.experiments.stats.PairBootstrap` for every model, so the contrasts stay paired).
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import torch

from graspaug.experiments.stats import PairBootstrap, headline, mean_interval, paired_contrast
from graspaug.geometry.clusters import largest_cluster, outlier_percentage
from graspaug.nets.ae_critic import AutoEncoder
from graspaug.training.autoencoder import decode, encode

# the three models of the study, in the order they are decoded, tabled and drawn
MODEL_LABELS = {"ae": "AE", "ae_extra": "AE + extra epochs (λ = 0)", "ae_critic": "AE-Critic"}
# paired contrasts: name → (model A, model B), A − B
CONTRASTS = {
    "critic_vs_control": ("ae_critic", "ae_extra"),
    "critic_vs_ae": ("ae_critic", "ae"),
    "control_vs_ae": ("ae_extra", "ae"),
}
# (S,) the interpolation weights of the example pairs' figure
EXAMPLE_ALPHAS = np.linspace(0, 1, 7, dtype=np.float32)


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
    """(P, A, R, R, R) bool: the pairs of latents ``z`` (N, d) interpolated at ``alphas`` (A,), decoded, thresholded."""
    probs = decode(ae, interpolate(z, pairs, alphas).reshape(-1, z.shape[1]), device)
    return (probs > threshold).reshape(len(pairs), len(alphas), *probs.shape[1:])


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


def outlier_columns(summary: dict[str, dict[str, dict]], alphas, keys: list[str]) -> dict[str, list]:
    """The outlier table, one row per α (``alphas``, named ``keys`` in ``summary``) and one column per
    model and interval end: ``alpha``, ``<model>``, …, ``<model>_low``, ``<model>_high``, …
    ``summary``: model → α key → :func:`~graspaug.experiments.stats.mean_interval` dict (outlier %)."""
    columns = {m: [s[k]["mean"] for k in keys] for m, s in summary.items()}
    bounds = {f"{m}_{end}": [s[k][f"ci_{end}"] for k in keys] for m, s in summary.items() for end in ("low", "high")}
    return {"alpha": list(alphas), **columns, **bounds}


def interpolation_rows(sequences: dict[str, np.ndarray], labels: dict[str, str]) -> tuple[list[list[tuple]], list[str]]:
    """The cells of the interpolations figure: per example pair, one row per model of its decoded
    grids (A, R, R, R) bool with their largest cluster; and the row labels (``pair <p> <label>``)."""
    rows, row_labels = [], []
    n_examples = len(next(iter(sequences.values()))) if sequences else 0
    for p in range(n_examples):
        for name, label in labels.items():
            rows.append([(g, largest_cluster(g)) for g in sequences[name][p]])
            row_labels.append(f"pair {p + 1} {label}")
    return rows, row_labels


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


def outlier_lines(wide: pd.DataFrame) -> tuple[dict[str, np.ndarray], dict[str, tuple[np.ndarray, np.ndarray]]]:
    """What :func:`graspaug.plots.lines` draws of the :func:`outlier_columns` table ``wide`` (one row per α):
    per model label, its (A,) mean outlier % and its (low, high) interval ends, (A,) each."""
    series = {label: wide[m].to_numpy(dtype=float) for m, label in MODEL_LABELS.items()}
    intervals = {
        label: (wide[f"{m}_low"].to_numpy(dtype=float), wide[f"{m}_high"].to_numpy(dtype=float))
        for m, label in MODEL_LABELS.items()
    }
    return series, intervals


def example_rows(sequences: dict[str, np.ndarray]) -> tuple[list[list[tuple]], list[str], list[str]]:
    """What :func:`graspaug.plots.voxel_rows` draws of the example pairs' ``sequences`` (model → (E, S, R, R, R)
    bool, decoded at :data:`EXAMPLE_ALPHAS`): the :func:`interpolation_rows` cells and row labels (the models'
    short names: their label up to `` (``), and the column labels (``α=0.50``)."""
    rows, row_labels = interpolation_rows(sequences, {m: label.split(" (")[0] for m, label in MODEL_LABELS.items()})
    return rows, row_labels, [f"α={a:.2f}" for a in EXAMPLE_ALPHAS]


def contrast_text(contrast: dict[str, dict], keys: list[str]) -> list[str | None]:
    """Per α key, one contrast (α key → :func:`~graspaug.experiments.stats.paired_contrast` dict) as
    ``"+1.23 [+0.45, +2.01]"`` (percentage points), or None where it has no mean."""
    return [
        None if d["mean"] is None else f"{d['mean']:+.2f} [{d['ci_low']:+.2f}, {d['ci_high']:+.2f}]"
        for d in (contrast[k] for k in keys)
    ]
