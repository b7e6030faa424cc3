"""Do the networks rank the cell's outcomes? The arms' networks scored on the executed calibration grasps.

The ``grasp_calibration`` stage executes labelled grasps of the rendered test split in the robot
cell. Every trained network has already scored those datapoints (its test predictions), so each
arm's network gets a ROC AUC against what the cell did with them: how well it ranks the grasps that
held through the lift and the shake above those that did not. Arms are compared on the same
executed grasps (paired): no planner search, drop or sensor noise differs between them, which
makes the contrast far less noisy than pick success, and it isolates the network's ranking from
the planner. The contrasts are the ``sim`` stage's (:data:`graspaug.experiments.sim_report.CONTRASTS`)
among arms with a network.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

import numpy as np
import pandas as pd

from graspaug.errors import DataError
from graspaug.experiments.ap.numbers import test_predictions, test_rows
from graspaug.experiments.sim_report import CONTRASTS
from graspaug.experiments.stats import ObjectBootstrap, percentile_interval, t_interval, weighted_roc_auc
from graspaug.rng import shape_rng


def arm_scores(grasps: pd.DataFrame, seed_dirs: Mapping[int, Path], chosen: Mapping) -> dict[str, np.ndarray]:
    """Each arm's P(success) on the executed grasps: arm → (S, G) for the S training seeds of
    ``seed_dirs`` (seed → folder of its networks) and the G rows of ``grasps`` (the calibration
    table, its ``datapoint`` column: the row in the rendered dataset's index). ``chosen``: arm →
    (pool, ratio, base size), as :func:`graspaug.experiments.sim.arms` gives; arms without a
    network are left out. Raises DataError when a datapoint is not among a seed's test rows."""
    where = {}  # seed → each grasp's position among the seed's test predictions
    for seed, seed_dir in seed_dirs.items():
        where[seed] = pd.Index(test_rows(seed_dir)).get_indexer(grasps.datapoint.to_numpy())
        if (where[seed] < 0).any():
            raise DataError(
                f"sim: {int((where[seed] < 0).sum())} executed calibration grasps are not test datapoints of seed "
                f"{seed} ({seed_dir}): rerun `dvc repro grasp_calibration`"
            )
    scores = {}
    for arm, (pool, ratio, base_size) in chosen.items():
        if pool is not None:
            scores[arm] = np.stack(
                [test_predictions(seed_dir, (pool, base_size, ratio))[where[s]] for s, seed_dir in seed_dirs.items()]
            )
    return scores


def cell_ranking(grasps: pd.DataFrame, seed_dirs: Mapping[int, Path], chosen: Mapping, n_boot: int, seed: int) -> dict:
    """ROC AUC of each arm's network against the cell's outcomes (``executed_success``) of the
    executed calibration ``grasps`` (:func:`arm_scores`), and the paired contrasts between arms.

    Returns ``{"n_grasps", "n_objects", "reference": {"eps", "label"}, "arms": {arm: {"auc", "per_seed",
    "auc_label"}}, "contrasts": {name: {...}}}``: ``auc`` the mean over training seeds (``auc_label``:
    the same networks' ROC AUC against the grasps' labels instead; None when the grasps hold one label
    only); a contrast's ``mean`` is the mean over seeds of the AUC difference, ``ci_low``, ``ci_high``
    its 95 % bootstrap interval over the grasps' objects (shapes; one resample for every network),
    ``t_ci_low``, ``t_ci_high`` the t-interval over seeds, ``per_seed``. The robust ε and the label,
    scored the same way, are the reference. When every grasp had the same outcome there is nothing to
    rank: no arms, no contrasts, reference None."""
    y = grasps.executed_success.to_numpy(bool)
    counts = {"n_grasps": int(len(grasps)), "n_objects": int(grasps.shape_id.nunique())}
    if len(np.unique(y)) < 2:  # every grasp held, or none: nothing to rank
        return {**counts, "reference": None, "arms": {}, "contrasts": {}}
    scores = arm_scores(grasps, seed_dirs, chosen)
    full, resampled = auc_samples(y, scores, ranking_bootstrap(grasps, n_boot, seed))
    return {**counts, **ranking_summary(grasps, list(seed_dirs), scores, full, resampled)}


def ranking_summary(grasps: pd.DataFrame, seeds: list, scores: dict, full: dict, resampled: dict) -> dict:
    """The ``reference``, ``arms`` and ``contrasts`` of :func:`cell_ranking` from the arms' ``scores``
    (:func:`arm_scores`) and their AUCs ``full``, ``resampled`` (:func:`auc_samples`) for the training
    ``seeds`` in that order."""
    y, label = grasps.executed_success.to_numpy(bool), grasps.label.to_numpy(bool)
    seeds = [str(s) for s in seeds]
    rounded = lambda x: None if x is None or not np.isfinite(x) else round(float(x), 5)  # noqa: E731
    contrasts = {}
    for name, (arm, reference) in CONTRASTS.items():
        if arm not in full or reference not in full:
            continue
        per_seed = full[arm] - full[reference]
        lo, hi = percentile_interval((resampled[arm] - resampled[reference]).mean(axis=0))
        over_seeds = t_interval(per_seed)
        contrasts[name] = {
            "mean": rounded(per_seed.mean()),
            "ci_low": rounded(lo),
            "ci_high": rounded(hi),
            "t_ci_low": rounded(over_seeds["ci_low"]),
            "t_ci_high": rounded(over_seeds["ci_high"]),
            "n_seeds": over_seeds["n_seeds"],
            "per_seed": dict(zip(seeds, map(rounded, per_seed))),
        }
    return {
        "reference": {k: rounded(boot_auc(y, grasps[k].to_numpy(float), None)) for k in ("eps", "label")},
        "arms": {
            arm: {
                "auc": rounded(auc.mean()),
                "per_seed": dict(zip(seeds, map(rounded, auc))),
                "auc_label": rounded(np.mean([boot_auc(label, s, None) for s in scores[arm]])),
            }
            for arm, auc in full.items()
        },
        "contrasts": contrasts,
    }


def ranking_bootstrap(grasps: pd.DataFrame, n_boot: int, seed: int) -> ObjectBootstrap:
    """The resamples of the executed ``grasps``' shapes that every network's AUC is computed under."""
    return ObjectBootstrap(grasps.shape_id.to_numpy(), n_boot, shape_rng(seed, "sim", "ranking-bootstrap"))


def auc_samples(y: np.ndarray, scores: Mapping[str, np.ndarray], boot: ObjectBootstrap):
    """Each arm's ROC AUC against the outcomes ``y`` (G,) of its ``scores`` (arm → (S, G), :func:`arm_scores`):
    (arm → (S,) on all grasps, arm → (S, R) under the R resamples of ``boot``), one value per training seed."""
    full = {arm: np.array([boot_auc(y, s, None) for s in rows]) for arm, rows in scores.items()}
    return full, {arm: np.stack([boot_auc(y, s, boot) for s in rows]) for arm, rows in scores.items()}


def boot_auc(y: np.ndarray, score: np.ndarray, boot: ObjectBootstrap | None):
    """ROC AUC of ``score`` for ``y`` on all grasps (``boot`` None: a float) or under every
    resample of ``boot`` ((R,))."""
    if boot is None:
        return float(weighted_roc_auc(y, score, np.ones(len(y))))
    return boot.roc_auc(y, score)
