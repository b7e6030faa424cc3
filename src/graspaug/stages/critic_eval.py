"""Stage ``critic_eval``: the paper's critic study (Section IV-B).

Random pairs of train shapes are interpolated at each α with the AE and with the
AE-Critic (same pairs); every decoded grid is clustered with DBSCAN and the voxels
outside its largest cluster are outliers. Outputs: ``metrics/critic_eval.json``
(mean outlier % per model per α), ``reports/critic_eval/outliers.{csv,png}`` and
``reports/critic_eval/interpolations.png`` (AE row above AE-Critic row, per pair).
"""
from __future__ import annotations

import json
import logging

import numpy as np
import pandas as pd

from graspaug.config import Params
from graspaug.device import resolve_device
from graspaug.geometry.clusters import largest_cluster, outlier_percentage
from graspaug.io.atomic import atomic_path
from graspaug.io.checkpoints import load_autoencoder
from graspaug.io.tables import write_csv
from graspaug.plots import lines, voxel_rows
from graspaug.stages import StageError
from graspaug.paths import AE_CRITIC_MODEL, AE_MODEL, CRITIC_EVAL_METRICS, INTERPOLATIONS_PNG, OUTLIERS_CSV, OUTLIERS_PNG, SHAPES_TABLE, VOXELS
from graspaug.training.autoencoder import decode, encode, grids_by_split

log = logging.getLogger(__name__)

MODELS = {"ae": AE_MODEL, "ae_critic": AE_CRITIC_MODEL}


def random_pairs(n: int, n_shapes: int, n_pairs: int, rng: np.random.Generator) -> np.ndarray:
    """(P, 2) index pairs: ``n_shapes`` of ``n`` drawn at random, paired off at random, first ``n_pairs``."""
    chosen = rng.choice(n, size=min(n, n_shapes), replace=False)
    pairs = rng.permutation(chosen)[: 2 * (len(chosen) // 2)].reshape(-1, 2)
    return pairs[:n_pairs]


def interpolate(z: np.ndarray, pairs: np.ndarray, alphas: np.ndarray) -> np.ndarray:
    """(P, A, d) latents ``(1 − α) z_a + α z_b`` for every pair and weight."""
    a, b = z[pairs[:, 0]][:, None], z[pairs[:, 1]][:, None]
    return (1 - alphas[None, :, None]) * a + alphas[None, :, None] * b


def run(params: Params) -> None:
    cfg = params.critic_eval
    device = resolve_device(params.device)
    train = grids_by_split(VOXELS, SHAPES_TABLE)["train"]
    pairs = random_pairs(len(train), cfg.n_shapes, cfg.n_pairs, np.random.default_rng(params.seed))
    if len(pairs) == 0:
        raise StageError(f"critic_eval needs at least 2 train shapes, the split has {len(train)}")
    alphas = np.asarray(cfg.alphas, dtype=np.float32)
    seq_alphas = np.linspace(0, 1, 7, dtype=np.float32)
    examples = pairs[: cfg.n_examples]

    outlier_pct: dict[str, dict[str, float | None]] = {}
    empty_grids: dict[str, int] = {}
    sequences = {}
    for name, path in MODELS.items():
        ae, _, _ = load_autoencoder(path, params.ae.net)
        z = encode(ae, train, device)
        grids = decode(ae, interpolate(z, pairs, alphas).reshape(-1, z.shape[1]), device) > cfg.threshold
        pct = np.array([outlier_percentage(g) for g in grids]).reshape(len(pairs), len(alphas))
        outlier_pct[name] = {f"{a:.2f}": float(np.nanmean(pct[:, i])) if np.isfinite(pct[:, i]).any() else None for i, a in enumerate(cfg.alphas)}
        empty_grids[name] = int(np.isnan(pct).sum())
        seq = decode(ae, interpolate(z, examples, seq_alphas).reshape(-1, z.shape[1]), device) > cfg.threshold
        sequences[name] = seq.reshape(len(examples), len(seq_alphas), *seq.shape[1:])

    result = {"n_pairs": int(len(pairs)), "n_decoded_per_model": int(len(pairs) * len(alphas)), "outlier_pct": outlier_pct, "empty_grids": empty_grids}
    with atomic_path(CRITIC_EVAL_METRICS) as tmp:
        tmp.write_text(json.dumps(result, indent=2) + "\n")
    # one row per α, one column per model, so `dvc plots` draws one line per model
    wide = pd.DataFrame({"alpha": list(cfg.alphas), **{m: [outlier_pct[m][f"{a:.2f}"] for a in cfg.alphas] for m in MODELS}})
    write_csv(wide, OUTLIERS_CSV)
    lines(list(cfg.alphas), {m: wide[m].to_numpy(dtype=float) for m in MODELS}, OUTLIERS_PNG, "interpolation weight α", "mean outlier voxels (%)", f"Outliers of decoded interpolations ({len(pairs)} pairs)")

    rows, row_labels = [], []
    for p in range(len(examples)):
        for name, label in (("ae", "AE"), ("ae_critic", "AE-Critic")):
            rows.append([(g, largest_cluster(g)) for g in sequences[name][p]])
            row_labels.append(f"pair {p + 1} {label}")
    voxel_rows(rows, row_labels, [f"α={a:.2f}" for a in seq_alphas], INTERPOLATIONS_PNG, "Interpolations: AE (upper) vs AE-Critic (lower); outliers red")

    def fmt(values):
        return [None if v is None else round(v, 2) for v in values.values()]

    log.info("critic_eval: outlier %% at α %s: AE %s, AE-Critic %s", list(outlier_pct["ae"]), fmt(outlier_pct["ae"]), fmt(outlier_pct["ae_critic"]))
