"""``graspaug study cell-ranking``: do networks trained on more real shapes rank the cell's outcomes better, over
draws of the training data?

The ``sim`` stage scores each arm's networks on the grasps that ``grasp_calibration`` executed in the cell (ROC AUC
against the outcomes: :mod:`graspaug.experiments.cell.numbers`). This study does the same for the networks of
several projects that share the rendered dataset and the cell but were trained on different draws of the training
shapes (``data_seed``; e.g. the attribution study's ``draw<k>`` folders), and pools them: per draw the contrasts of
the ``sim`` stage (bootstrap over shapes, t over seeds), and over all draws one hierarchical interval over draws,
training seeds and shapes. Also, exploratory: each network's top-scored executed grasp per shape (a pick among the
shape's executed grasps), closer to what the planner does than the AUC. The outcomes are executed once (``grasps``,
the ``grasps.csv`` of a ``grasp_calibration`` run): they do not depend on the networks. Arms: ``before`` (targeted
B-0), ``after`` and ``real`` (B at each project's ratio chosen on validation AP: its AP report, or its targeted B
networks' validation AP), ``more_real`` (targeted ``more_real``-0, by default the largest base size). Each project's
``params.yaml`` is read; ``models`` names the networks' folder in it.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd

from graspaug.experiments.ap.numbers import choose_ratios, collect
from graspaug.experiments.cell.numbers import CONTRASTS, arm_scores, auc_samples, ranking_bootstrap, ranking_summary
from graspaug.experiments.cell.trials import after_ratio
from graspaug.experiments.stats import nested_t_interval
from graspaug.io.tables import read_table
from graspaug.pipeline.params.model import load_params
from graspaug.pipeline.paths import AP_REPORT
from graspaug.training.variants import Variant


def top_pick(grasps: pd.DataFrame, scores: dict[str, np.ndarray]) -> dict:
    """Exploratory, closer to what the planner does: per arm and training seed, the success rate of each
    network's top-scored executed grasp of every shape (one pick per shape among its executed grasps), and
    ``real_data`` (more_real − before) per seed."""
    picks = {}
    for arm, rows in scores.items():
        picks[arm] = [
            round(float(grasps.assign(p=p).loc[lambda d: d.groupby("shape_id").p.idxmax()].executed_success.mean()), 4)
            for p in rows
        ]
    if "more_real" in picks:
        picks["real_data"] = [round(a - b, 4) for a, b in zip(picks["more_real"], picks["before"])]
    return picks


def project_arms(project: Path, params, models: Path, seeds, base_size: int, more_real: int | None) -> dict:
    """The ``sim`` stage's network arms in ``project`` (its ``params``): "after" at the ratio of its AP report
    (``reports/gqcnn/ap.json``) for the networks of ``models/gqcnn``, else of the best mean validation AP of the
    targeted B networks in ``models``; more_real at ``more_real`` or the largest base size."""
    report = project / AP_REPORT  # it describes the networks of models/gqcnn only
    if models == Path("models/gqcnn") and report.exists():
        best, _ = after_ratio(json.loads(report.read_text()), base_size, params.generate.ratios)
    else:
        nonzero = [Variant("targeted", base_size, float(r)) for r in params.generate.ratios if r > 0]
        runs = collect({s: project / models / f"s{s}" for s in seeds}, nonzero)
        best = choose_ratios(runs, [base_size])[base_size]
    larger = more_real or max(params.generate.base_sizes)
    return {
        "before": ("targeted", 0.0, base_size),
        "after": ("targeted", best, base_size),
        "real": ("real", best, base_size),
        "more_real": ("targeted", 0.0, larger),
    }


def run(
    grasps_csv: Path, projects: list[Path], models: Path, seeds: list[int] | None, base_size: int, more_real: int | None
) -> dict:
    """The ranking per project (draw) and pooled over them (one JSON object: ``grasps``, ``shapes``, ``reference``,
    ``draws``, ``pooled``; a pooled contrast is None with one project)."""
    params = load_params(projects[0] / "params.yaml")
    grasps = read_table(grasps_csv)
    boot = ranking_bootstrap(grasps, params.sim.n_bootstrap, params.seed)
    draws, full, resampled = {}, [], []
    for project in projects:
        params = load_params(project / "params.yaml")
        used = seeds if seeds is not None else list(params.gqcnn.seeds)
        chosen = project_arms(project, params, models, used, base_size, more_real)
        seed_dirs = {s: project / models / f"s{s}" for s in used}
        scores = arm_scores(grasps, seed_dirs, chosen)
        f, r = auc_samples(grasps.executed_success.to_numpy(bool), scores, boot)  # the sim stage's resamples
        ranking = ranking_summary(grasps, used, scores, f, r)
        draws[str(project)] = {"arms_networks": chosen, "arms": ranking["arms"], "contrasts": ranking["contrasts"]}
        draws[str(project)]["top_pick"] = top_pick(grasps, scores)
        full.append(f)
        resampled.append(r)
    pooled = {}
    for name, (arm, reference) in CONTRASTS.items():
        if arm in full[0] and reference in full[0]:
            f = np.stack([d[arm] - d[reference] for d in full])  # (D, S)
            r = np.stack([d[arm] - d[reference] for d in resampled])  # (D, S, R)
            pooled[name] = nested_t_interval(f, r) if len(full) > 1 else None
    summary = {"grasps": len(grasps), "shapes": int(grasps.shape_id.nunique()), "reference": ranking["reference"]}
    return {**summary, "draws": draws, "pooled": pooled}
