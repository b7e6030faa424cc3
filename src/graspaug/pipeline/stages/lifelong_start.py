"""Stage ``lifelong_start``: round 0 of the lifelong loop, the base set alone (``lifelong.base_size``).

Scores every validation object by the ``targeted`` B-0 networks of ``train_gqcnn`` (mean log loss of their
predictions averaged over the seeds; the test split never chooses) and marks the ``lifelong.worst`` as the failures
that round 1 generates from. Writes ``data/lifelong/r0/`` (``failures.csv``, ``history.csv``, ``curve.csv``),
``metrics/lifelong/r0/`` (the round-0 networks' test AP) and ``reports/lifelong/r0/``.
"""

from __future__ import annotations

import logging

import numpy as np

from graspaug.experiments.ap.numbers import test_labels
from graspaug.experiments.lifelong.numbers import arm_variant, failure_history, validation_errors
from graspaug.experiments.lifelong.round import write_round
from graspaug.io.atomic import atomic_path
from graspaug.io.tables import read_table
from graspaug.io.voxels import read_voxels
from graspaug.pipeline import paths
from graspaug.pipeline.params.base import params_model
from graspaug.pipeline.params.generate import GenerateParams
from graspaug.pipeline.params.gqcnn import GQCNNParams
from graspaug.pipeline.params.lifelong import LifelongParams
from graspaug.pipeline.provenance import report_header
from graspaug.pipeline.stages import StageError

log = logging.getLogger(__name__)

Params = params_model(
    "The params the `lifelong_start` stage reads.", generate=GenerateParams, gqcnn=GQCNNParams, lifelong=LifelongParams
)


def run(params: Params) -> None:
    cfg, gq = params.lifelong, params.gqcnn
    if cfg.base_size not in params.generate.base_sizes:
        raise StageError(
            f"lifelong.base_size {cfg.base_size} is not in generate.base_sizes {params.generate.base_sizes}"
        )
    seed_dirs = {s: paths.gqcnn_seed_dir(s) for s in gq.seeds}
    index = read_table(paths.gqcnn_dir("original") / "index.parquet")
    start = arm_variant("none", cfg.base_size, 0).name
    errors, _ = validation_errors(seed_dirs, start, index)
    chosen = list(errors.index[: cfg.worst])
    history = failure_history(None, 0, chosen)
    labels, objects = test_labels(index, seed_dirs[gq.seeds[0]])
    networks = {params.data_seed: {s: {"none": folder / start} for s, folder in seed_dirs.items()}}
    with atomic_path(paths.lifelong_data(0), directory=True) as folder:
        errors.assign(chosen=errors.index.isin(chosen)).to_csv(folder / "failures.csv")
        history.to_csv(folder / "history.csv", index=False)
        reports = paths.lifelong_metrics(0), paths.lifelong_reports(0)
        header = report_header(params.file_text, read_table(paths.SHAPES_TABLE))  # the profile and corpus
        voxels = read_voxels(paths.VOXELS)
        curve = write_round(0, networks, labels, objects, None, history, params, voxels, *reports, header=header)
        curve.to_csv(folder / "curve.csv", index=False)
    log.info("lifelong r0: failures %s (validation AP %s)", chosen, np.round(errors.ap.loc[chosen].to_numpy(), 3))


if __name__ == "__main__":
    from graspaug.pipeline.entry import stage_main

    stage_main(__spec__.name)
