"""Stage ``critic_eval``: the paper's critic study (Section IV-B), with a control and intervals.

Random pairs of train shapes are interpolated at each α by three models on the same pairs:
the AE (phase 1), the control (phase 2 with λ = 0) and the AE-Critic. Every decoded grid is
clustered with DBSCAN; voxels outside its largest cluster are outliers. Outputs:
``metrics/critic_eval.json`` (per model and α the mean outlier % with a bootstrap 95% interval
over pairs; paired contrasts; the critic's AUC on held-out shapes),
``reports/critic_eval/outliers.{csv,png}`` and ``reports/critic_eval/interpolations.png``
(the paper's Fig. 5: AE / control / AE-Critic rows per pair, main part green, outliers red).
"""

from __future__ import annotations

import logging

import numpy as np
import pandas as pd

from graspaug.device import resolve_device
from graspaug.experiments.critic import (
    decoded_interpolations,
    interpolation_rows,
    outlier_columns,
    outlier_contrast,
    outlier_table,
    random_pairs,
    summarize,
)
from graspaug.experiments.stats import PairBootstrap
from graspaug.io.checkpoints import load_autoencoder
from graspaug.io.tables import write_csv, write_json
from graspaug.params.ae import AEParams
from graspaug.params.base import params_model
from graspaug.params.critic_eval import CriticEvalParams
from graspaug.paths import (
    AE_CRITIC_MODEL,
    AE_EXTRA_MODEL,
    AE_MODEL,
    CRITIC_EVAL_METRICS,
    INTERPOLATIONS_PNG,
    OUTLIERS_CSV,
    OUTLIERS_PNG,
    SHAPES_TABLE,
    VOXELS,
)
from graspaug.plots import lines, voxel_rows
from graspaug.stages import StageError
from graspaug.training.autoencoder import critic_separation, encode, grids_by_split

log = logging.getLogger(__name__)

Params = params_model("The params the `critic_eval` stage reads.", ae=AEParams, critic_eval=CriticEvalParams)

MODELS = {
    "ae": (AE_MODEL, "AE"),
    "ae_extra": (AE_EXTRA_MODEL, "AE + extra epochs (λ = 0)"),
    "ae_critic": (AE_CRITIC_MODEL, "AE-Critic"),
}
CONTRASTS = {
    "critic_vs_control": ("ae_critic", "ae_extra"),
    "critic_vs_ae": ("ae_critic", "ae"),
    "control_vs_ae": ("ae_extra", "ae"),
}


def run(params: Params) -> None:
    cfg = params.critic_eval
    device = resolve_device(params.device)
    grids = grids_by_split(VOXELS, SHAPES_TABLE)
    rng = np.random.default_rng(params.seed)
    pairs = random_pairs(len(grids["train"]), cfg.n_shapes, cfg.n_pairs, rng)
    if len(pairs) == 0:
        raise StageError(f"critic_eval needs at least 2 train shapes, the split has {len(grids['train'])}")
    boot = PairBootstrap(len(pairs), cfg.n_bootstrap, rng)
    alphas = np.asarray(cfg.alphas, dtype=np.float32)
    keys = [f"{a:.2f}" for a in cfg.alphas]
    seq_alphas = np.linspace(0, 1, 7, dtype=np.float32)
    examples = pairs[: cfg.n_examples]

    pct, sequences, critic = {}, {}, None
    for name, (path, _) in MODELS.items():
        ae, model_critic, _ = load_autoencoder(path, params.ae.net)
        z = encode(ae, grids["train"], device)
        pct[name] = outlier_table(decoded_interpolations(ae, z, pairs, alphas, cfg.threshold, device))
        sequences[name] = decoded_interpolations(ae, z, examples, seq_alphas, cfg.threshold, device)
        if name == "ae_critic":
            if model_critic is None:
                raise StageError(f"{path} holds no critic; retrain it with `dvc repro train_ae`")
            separation = critic_separation(ae, model_critic, grids["test"], device)
            critic = {k: v if np.isfinite(v) else None for k, v in separation.items()}

    summary = {name: dict(zip(keys, summarize(pct[name], boot))) for name in MODELS}
    contrast = {c: dict(zip(keys, outlier_contrast(pct[a], pct[b], boot))) for c, (a, b) in CONTRASTS.items()}
    write_json(
        {
            "n_pairs": int(len(pairs)),
            "n_decoded_per_model": int(pct["ae"].size),
            "n_bootstrap": cfg.n_bootstrap,
            "critic_auc": critic["auc"],
            "critic": critic,
            "outlier_pct": {name: {k: v["mean"] for k, v in summary[name].items()} for name in MODELS},
            "outlier_pct_ci": summary,
            "contrast": contrast,
            "empty_grids": {name: int(np.isnan(pct[name]).sum()) for name in MODELS},
        },
        CRITIC_EVAL_METRICS,
    )

    # one row per α, one column per model (and its interval), so `dvc plots` draws one line per model
    wide = pd.DataFrame(outlier_columns(summary, cfg.alphas, keys))
    write_csv(wide, OUTLIERS_CSV)
    labels = {m: label for m, (_, label) in MODELS.items()}
    lines(
        list(cfg.alphas),
        {label: wide[m].to_numpy(dtype=float) for m, label in labels.items()},
        OUTLIERS_PNG,
        "interpolation weight α",
        "mean outlier voxels (%)",
        f"Outliers of decoded interpolations ({len(pairs)} pairs, 95% bootstrap intervals)",
        intervals={
            label: (wide[f"{m}_low"].to_numpy(dtype=float), wide[f"{m}_high"].to_numpy(dtype=float))
            for m, label in labels.items()
        },
    )
    rows, row_labels = interpolation_rows(sequences, {m: label.split(" (")[0] for m, label in labels.items()})
    voxel_rows(
        rows,
        row_labels,
        [f"α={a:.2f}" for a in seq_alphas],
        INTERPOLATIONS_PNG,
        "Interpolations per pair: AE, AE + extra epochs (λ = 0), AE-Critic; main part green, outliers red",
    )

    diff = contrast["critic_vs_control"]
    log.info(
        "critic_eval: critic AUC %s; AE-Critic − control outlier %% at α %s: %s",
        critic["auc"],
        keys,
        [
            None if d["mean"] is None else f"{d['mean']:+.2f} [{d['ci_low']:+.2f}, {d['ci_high']:+.2f}]"
            for d in (diff[k] for k in keys)
        ],
    )
