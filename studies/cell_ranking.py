"""Do networks trained on more real shapes rank the cell's outcomes better, over draws of the training data?

The ``sim`` stage scores each arm's networks on the grasps that ``grasp_calibration`` executed in
the cell (ROC AUC against the outcomes: :mod:`graspaug.experiments.cell_ranking`). This study does
the same for the networks of several projects that share the rendered dataset and the cell but were
trained on different draws of the training shapes (``data_seed``; e.g. the attribution study's
``draw<k>`` folders), and pools them: per draw the contrasts of the ``sim`` stage (bootstrap over
shapes, t over seeds), and over all draws one hierarchical interval over draws, training seeds and
shapes. Also, exploratory: each network's top-scored executed grasp per shape (a pick among the
shape's executed grasps), closer to what the planner does than the AUC. The outcomes are executed
once (``--grasps``, the ``grasps.csv`` of a ``grasp_calibration`` run): they do not depend on the
networks. Arms: ``before`` (targeted B-0), ``after`` and ``real`` (B at each project's ratio chosen
on validation AP), ``more_real`` (targeted ``--more-real``-0). Prints one JSON line.

    python studies/cell_ranking.py --grasps reports/grasp_calibration/grasps.csv \\
        --projects . ../draw1 ../draw2 [--seeds 0 1 2 3] [--base-size 50] [--more-real 200]
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np
import pandas as pd

from graspaug.config import Params
from graspaug.experiments.cell_ranking import arm_scores, auc_samples, cell_ranking, ranking_bootstrap
from graspaug.experiments.sim import after_ratio
from graspaug.experiments.sim_report import CONTRASTS
from graspaug.experiments.stats import nested_interval
from graspaug.io.tables import read_table
from graspaug.rng import shape_rng


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


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--grasps", type=Path, required=True, help="grasps.csv of a grasp_calibration run")
    parser.add_argument("--projects", type=Path, nargs="+", required=True, help="one project folder per draw")
    parser.add_argument("--seeds", type=int, nargs="+", default=[0, 1, 2, 3])
    parser.add_argument("--base-size", type=int, default=50)
    parser.add_argument("--more-real", type=int, default=200)
    args = parser.parse_args()
    params = Params()
    grasps = read_table(args.grasps)
    boot = ranking_bootstrap(grasps, params.sim.n_bootstrap, params.seed)
    draws, full, resampled = {}, [], []
    for project in args.projects:
        ap = json.loads((project / "reports/gqcnn/ap.json").read_text())
        best, _ = after_ratio(ap, args.base_size, params.generate.ratios)
        chosen = {
            "before": ("targeted", 0.0, args.base_size),
            "after": ("targeted", best, args.base_size),
            "real": ("real", best, args.base_size),
            "more_real": ("targeted", 0.0, args.more_real),
        }
        seed_dirs = {s: project / f"models/gqcnn/s{s}" for s in args.seeds}
        ranking = cell_ranking(grasps, seed_dirs, chosen, params.sim.n_bootstrap, params.seed)
        draws[str(project)] = {"after_ratio": best, "arms": ranking["arms"], "contrasts": ranking["contrasts"]}
        scores = arm_scores(grasps, seed_dirs, chosen)
        draws[str(project)]["top_pick"] = top_pick(grasps, scores)
        f, r = auc_samples(grasps.executed_success.to_numpy(bool), scores, boot)
        full.append(f)
        resampled.append(r)
    rng = shape_rng(params.seed, "sim", "ranking-draws")
    pooled = {}
    for name, (arm, reference) in CONTRASTS.items():
        if arm in full[0] and reference in full[0]:
            f = np.stack([d[arm] - d[reference] for d in full])  # (D, S)
            r = np.stack([d[arm] - d[reference] for d in resampled])  # (D, S, R)
            pooled[name] = nested_interval(f, r, rng)
    summary = {"grasps": len(grasps), "shapes": int(grasps.shape_id.nunique()), "reference": ranking["reference"]}
    print(json.dumps({**summary, "draws": draws, "pooled": pooled}))


if __name__ == "__main__":
    main()
