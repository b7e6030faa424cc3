"""Stage ``critic_eval``: the paper's critic study (Section IV-B), with a control and intervals.

Random pairs of train shapes are interpolated at each α by three models on the same pairs: the AE (phase 1),
the control (phase 2 with λ = 0) and the AE-Critic. Every decoded grid is clustered with DBSCAN; voxels outside
its largest cluster are outliers. Outputs: ``metrics/critic_eval.json`` (AE-Critic − control over the
interpolants with its interval, the critic's AUC), ``reports/critic_eval/study.json`` (per model and α the mean
outlier % with a bootstrap 95% interval over pairs; paired contrasts; the critic's AUC on held-out shapes),
``outliers.{csv,png}`` and ``interpolations.png`` (Fig. 5: AE / control / AE-Critic rows per pair) beside it.
"""

from __future__ import annotations

import logging

import numpy as np
import pandas as pd

from graspaug.device import resolve_device
from graspaug.experiments.critic.figures import EXAMPLE_ALPHAS, example_rows, outlier_columns, outlier_lines
from graspaug.experiments.critic.numbers import (
    finite_or_none,
    model_interpolations,
    random_pairs,
    study_headline,
    study_metrics,
)
from graspaug.experiments.critic.words import contrast_text
from graspaug.experiments.stats import PairBootstrap
from graspaug.io.checkpoints import load_autoencoder
from graspaug.io.tables import write_csv, write_json
from graspaug.pipeline.params.ae import AEParams
from graspaug.pipeline.params.base import params_model
from graspaug.pipeline.params.critic_eval import CriticEvalParams
from graspaug.pipeline.paths import (
    AE_CRITIC_MODEL,
    AE_EXTRA_MODEL,
    AE_MODEL,
    CRITIC_EVAL_METRICS,
    CRITIC_EVAL_STUDY,
    INTERPOLATIONS_PNG,
    OUTLIERS_CSV,
    OUTLIERS_PNG,
    SHAPES_TABLE,
    VOXELS,
)
from graspaug.pipeline.stages import StageError
from graspaug.plots import lines, voxel_rows
from graspaug.training.autoencoder import critic_separation, grids_by_split

log = logging.getLogger(__name__)

Params = params_model("The params the `critic_eval` stage reads.", ae=AEParams, critic_eval=CriticEvalParams)

MODEL_FILES = {"ae": AE_MODEL, "ae_extra": AE_EXTRA_MODEL, "ae_critic": AE_CRITIC_MODEL}  # experiments.critic's models


def run(params: Params) -> None:
    cfg = params.critic_eval
    device = resolve_device(params.device)
    grids = grids_by_split(VOXELS, SHAPES_TABLE, params.ae.net.output)
    rng = np.random.default_rng(params.seed)
    pairs = random_pairs(len(grids["train"]), cfg.n_shapes, cfg.n_pairs, rng)
    if len(pairs) == 0:
        raise StageError(f"critic_eval needs at least 2 train shapes, the split has {len(grids['train'])}")
    boot = PairBootstrap(len(pairs), cfg.n_bootstrap, rng)
    alphas = np.asarray(cfg.alphas, dtype=np.float32)
    keys = [f"{a:.2f}" for a in cfg.alphas]

    pct, sequences, critic = {}, {}, None
    for name, path in MODEL_FILES.items():
        ae, model_critic, _ = load_autoencoder(path, params.ae.net)
        pct[name], sequences[name] = model_interpolations(
            ae, grids["train"], pairs, pairs[: cfg.n_examples], alphas, EXAMPLE_ALPHAS, cfg.threshold, device
        )
        if name == "ae_critic":
            if model_critic is None:
                raise StageError(f"{path} holds no critic; retrain it with `dvc repro train_ae`")
            critic = finite_or_none(critic_separation(ae, model_critic, grids["test"], device))

    metrics = study_metrics(pct, boot, keys, critic, cfg.n_bootstrap)
    write_json(metrics, CRITIC_EVAL_STUDY)
    write_json(study_headline(metrics), CRITIC_EVAL_METRICS)
    # one row per α, one column per model (and its interval), so `dvc plots` draws one line per model
    wide = pd.DataFrame(outlier_columns(metrics["outlier_pct_ci"], cfg.alphas, keys))
    write_csv(wide, OUTLIERS_CSV)
    series, intervals = outlier_lines(wide)
    title = f"Outliers of decoded interpolations ({len(pairs)} pairs, 95% bootstrap intervals)"
    lines(list(cfg.alphas), series, OUTLIERS_PNG, "interpolation weight α", "mean outlier voxels (%)", title, intervals)
    voxel_rows(
        *example_rows(sequences),
        INTERPOLATIONS_PNG,
        "Interpolations per pair: AE, AE + extra epochs (λ = 0), AE-Critic; main part green, outliers red",
    )
    text = contrast_text(metrics["contrast"]["critic_vs_control"], keys)
    auc = "undefined" if critic["auc"] is None else f"{critic['auc']:.3f}"
    log.info("critic_eval: critic AUC %s; AE-Critic − control outlier %% at α %s: %s", auc, keys, text)


if __name__ == "__main__":
    from graspaug.pipeline.entry import stage_main

    stage_main(__spec__.name)
